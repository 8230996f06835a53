#include "integrators/ImplicitEuler.h"

#include <weft/threading/FrameClock.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>

namespace weft {

void ImplicitEuler::reset() { m_hasWarmStart = false; }

void ImplicitEuler::saveCarriedState(Vec3Array& out) const {
  if (m_hasWarmStart) out = m_deltaV;
  else out.clear();
}

void ImplicitEuler::restoreCarriedState(const Vec3Array& in) {
  if (in.empty()) {
    reset();
    return;
  }
  resize(Index(in.size()));
  m_deltaV = in;
  m_hasWarmStart = true;
}

void ImplicitEuler::resize(Index vertexCount) {
  if (m_deltaV.size() == vertexCount) return;
  m_pcg.resize(vertexCount);
  m_filter.resize(vertexCount);
  m_filteredVertices.clear();
  for (Vec3Array* array : {&m_deltaV, &m_correction, &m_force, &m_stiffnessTimesVelocity,
                           &m_rightHandSide, &m_iteratePosition, &m_iterateVelocity,
                           &m_prescribedPosition, &m_prescribedVelocity}) {
    array->assign(vertexCount, Vec3::Zero());
  }
  m_hasWarmStart = false;
}

void ImplicitEuler::solve(DynamicSystem& system, IntegratorReport& report) {
  PcgSettings pcgSettings;
  pcgSettings.tolerance = m_settings.cgTolerance;
  pcgSettings.maxIterations = m_settings.cgMaxIterations;
  pcgSettings.warmStart = true;  // the caller prepares the initial guess in m_correction
  pcgSettings.preconditioner = m_settings.preconditioner;
  WEFT_PROFILE_ZONE("solve");
  const std::int64_t start = FrameClock::nowNs();
  const SolveReport solve = m_pcg.solve(system.systemMatrix(), m_rightHandSide, m_filter,
                                        pcgSettings, m_correction, system.taskSystem());
  report.solveMs += FrameClock::msSince(start);
  ++report.linearSolves;
  report.cgIterations += solve.iterations;
  report.cgResidual = solve.relativeResidual;
  report.cgConverged = report.cgConverged && solve.converged;
}

void ImplicitEuler::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                         IntegratorReport& report) {
  const Index n = system.vertexCount();
  resize(n);
  const std::vector<Real>& masses = system.masses();

  // Pins: the velocity change that puts each pinned vertex exactly on its target at t + h.
  for (Index vertex : m_filteredVertices) m_filter.setFree(vertex);
  m_filteredVertices.assign(system.prescribedVertices().begin(), system.prescribedVertices().end());
  // applyPrescribedMotion writes every prescribed entry, and only those are read below.
  system.applyPrescribedMotion(t + h, m_prescribedPosition, m_prescribedVelocity);
  for (Index vertex : m_filteredVertices) {
    m_filter.setFixed(vertex, (m_prescribedPosition[vertex] - x[vertex]) / h - v[vertex]);
  }
  // Contacts with colliders: one constrained direction each.
  system.constrainContacts(x, v, h, m_filter);

  // Baraff–Witkin step, expanded about (x_n, v_n).
  {
    WEFT_PROFILE_ZONE("assembly");
    const std::int64_t start = FrameClock::nowNs();
    report.potentialEnergy = system.linearize(x, v, t, h, m_force, v, m_stiffnessTimesVelocity);
    report.assemblyMs += FrameClock::msSince(start);
  }
  for (Index i = 0; i < n; ++i) {
    m_rightHandSide[i] = h * (m_force[i] + h * m_stiffnessTimesVelocity[i]);
  }
  // Initial guess: last step's Δv (warm start) or zero; the filter puts pinned entries on target.
  for (Index i = 0; i < n; ++i) {
    m_correction[i] = (m_settings.warmStart && m_hasWarmStart) ? m_deltaV[i] : Vec3::Zero();
  }
  solve(system, report);
  m_deltaV = m_correction;

  // Newton iterations on M Δv = h f(x_n + h(v_n + Δv), v_n + Δv); pinned vertices stay on target.
  if (m_settings.newtonIterations > 0) {
    for (Index vertex : m_filteredVertices) m_filter.setFixed(vertex, Vec3::Zero());
    // Contact constraints are met by Δv already: corrections stay tangent to the contacts.
    for (Index vertex = 0; vertex < n; ++vertex) {
      if (m_filter.kind(vertex) == ConstraintKind::OneDirection) {
        m_filter.setConstrained(vertex, m_filter.direction(vertex, 0), Vec3::Zero());
      }
    }
  }
  for (int iteration = 0; iteration < m_settings.newtonIterations; ++iteration) {
    for (Index i = 0; i < n; ++i) {
      m_iterateVelocity[i] = v[i] + m_deltaV[i];
      m_iteratePosition[i] = x[i] + h * m_iterateVelocity[i];
    }
    {
      WEFT_PROFILE_ZONE("assembly");
      const std::int64_t start = FrameClock::nowNs();
      system.linearize(m_iteratePosition, m_iterateVelocity, t + h, h, m_force, m_iterateVelocity,
                       m_stiffnessTimesVelocity);
      report.assemblyMs += FrameClock::msSince(start);
    }
    for (Index i = 0; i < n; ++i) {
      m_rightHandSide[i] = h * m_force[i] - masses[i] * m_deltaV[i];
      m_correction[i].setZero();
    }
    solve(system, report);
    for (Index i = 0; i < n; ++i) m_deltaV[i] += m_correction[i];
  }

  for (Index i = 0; i < n; ++i) {
    v[i] += m_deltaV[i];
    x[i] += h * v[i];
  }
  // Exact pin positions (the filter already made them exact up to round-off).
  system.applyPrescribedMotion(t + h, x, v);
  m_hasWarmStart = true;
}

}  // namespace weft
