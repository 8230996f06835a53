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
  resizeVertices(Index(in.size()));
  m_deltaV = in;
  m_hasWarmStart = true;
}

void ImplicitEuler::rotateCarriedState(const Mat3& rotation) {
  if (!m_hasWarmStart) return;
  for (Vec3& deltaV : m_deltaV) deltaV = rotation * deltaV;
}

void ImplicitEuler::resizeVertices(Index vertexCount) {
  if (m_deltaV.size() == vertexCount) return;
  for (Vec3Array* array : {&m_deltaV, &m_force, &m_stiffnessTimesVelocity, &m_rightHandSide,
                           &m_iteratePosition, &m_iterateVelocity, &m_prescribedPosition,
                           &m_prescribedVelocity}) {
    array->assign(vertexCount, Vec3::Zero());
  }
  m_hasWarmStart = false;
}

void ImplicitEuler::resizeRows(Index rowCount) {
  if (m_correction.size() == rowCount && m_filter.size() == rowCount) return;
  m_pcg.resize(rowCount);
  m_filter.resize(rowCount);
  m_filteredRows.clear();
  m_correction.assign(rowCount, Vec3::Zero());
  m_rowRightHandSide.assign(rowCount, Vec3::Zero());
  m_rowMass.assign(rowCount, 0);
}

void ImplicitEuler::solve(DynamicSystem& system, IntegratorReport& report) {
  m_pcg.setRowColors(system.rowColors());  // the Gauss–Seidel order: the system's, not the pattern's
  PcgSettings pcgSettings;
  pcgSettings.tolerance = m_settings.cgTolerance;
  pcgSettings.maxIterations = m_settings.cgMaxIterations;
  pcgSettings.warmStart = true;  // the caller prepares the initial guess in m_correction
  pcgSettings.preconditioner = m_settings.preconditioner;
  // The stopping test (SolverSettings::cgStopping); the velocity-error one weighs by the masses.
  pcgSettings.stopping = m_settings.cgStopping;
  WEFT_PROFILE_ZONE("solve");
  const std::int64_t start = FrameClock::nowNs();
  const SolveReport solve = m_pcg.solve(system.systemMatrix(), m_rowRightHandSide, m_filter,
                                        pcgSettings, m_correction, system.taskSystem(), m_rowMass);
  report.solveMs += FrameClock::msSince(start);
  ++report.linearSolves;
  report.cgIterations += solve.iterations;
  report.cgResidual = solve.relativeResidual;
  report.cgConverged = report.cgConverged && solve.converged;
  report.solvedUnknowns = 3 * Index(m_correction.size());
}

void ImplicitEuler::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                         IntegratorReport& report) {
  const Index n = system.vertexCount();
  resizeVertices(n);
  const FreeVertexMap* systemMap = system.freeVertexMap();
  if (!systemMap && m_identityMap.vertexCount() != n) m_identityMap.build(n, {});
  const FreeVertexMap& map = systemMap ? *systemMap : m_identityMap;
  const Index rows = map.rowCount();
  resizeRows(rows);
  const std::vector<Real>& masses = system.masses();
  for (Index row = 0; row < rows; ++row) m_rowMass[row] = masses[map.vertex(row)];

  // Pins: the velocity change that puts each pinned vertex exactly on its target at t + h. A pin
  // with a row is fixed in the filter; a removed one keeps its Δv in m_deltaV, where the
  // coupling product below and the update at the end read it.
  for (Index row : m_filteredRows) m_filter.setFree(row);
  m_filteredRows.clear();  // keeps its capacity: no allocation after the first step
  // applyPrescribedMotion writes every prescribed entry, and only those are read below.
  system.applyPrescribedMotion(t + h, m_prescribedPosition, m_prescribedVelocity);
  bool removedPins = false;
  for (Index vertex : system.prescribedVertices()) {
    const Vec3 target = (m_prescribedPosition[vertex] - x[vertex]) / h - v[vertex];
    const Index row = map.row(vertex);
    if (row == kInvalidIndex) {
      m_deltaV[vertex] = target;
      removedPins = true;
    } else {
      m_filter.setFixed(row, target);
      m_filteredRows.push_back(row);
    }
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
  map.gather(m_rightHandSide, m_rowRightHandSide);
  // b_f − A_fp Δv_p: the pull of removed pins on their free neighbours.
  if (removedPins) system.subtractPrescribedCoupling(m_deltaV, m_rowRightHandSide);
  // Initial guess: last step's Δv (warm start) or zero; the filter puts fixed entries on target.
  if (m_settings.warmStart && m_hasWarmStart) {
    map.gather(m_deltaV, m_correction);
  } else {
    for (Index row = 0; row < rows; ++row) m_correction[row].setZero();
  }
  solve(system, report);
  map.scatter(m_correction, m_deltaV);

  // Newton iterations on M Δv = h f(x_n + h(v_n + Δv), v_n + Δv); pinned vertices stay on target
  // (their correction is zero, so removed pins add nothing to the right-hand side).
  if (m_settings.newtonIterations > 0) {
    for (Index row : m_filteredRows) m_filter.setFixed(row, Vec3::Zero());
    // Contact constraints are met by Δv already: corrections stay tangent to the contacts.
    for (Index row = 0; row < rows; ++row) {
      if (m_filter.kind(row) == ConstraintKind::OneDirection) {
        m_filter.setConstrained(row, m_filter.direction(row, 0), Vec3::Zero());
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
    for (Index i = 0; i < n; ++i) m_rightHandSide[i] = h * m_force[i] - masses[i] * m_deltaV[i];
    map.gather(m_rightHandSide, m_rowRightHandSide);
    for (Index row = 0; row < rows; ++row) m_correction[row].setZero();
    solve(system, report);
    for (Index row = 0; row < rows; ++row) m_deltaV[map.vertex(row)] += m_correction[row];
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
