// The four explicit integrators: explicit Euler, symplectic Euler, explicit midpoint and RK4.
//
// Each stage evaluates accelerations a = f / m for the free vertices and overwrites prescribed
// vertices with their scripted motion at the stage time, so pins are exact at every stage.
// Scratch arrays are sized on the first step and reused: no allocation in steady state.
#include "integrators/ExplicitIntegrators.h"

#include <weft/threading/FrameClock.h>
#include <weft/threading/Profiler.h>

namespace weft {
namespace {

// a = f / m for free vertices; prescribed vertices get zero (their motion is scripted).
void accelerations(DynamicSystem& system, const Vec3Array& x, const Vec3Array& v, Real t,
                   Vec3Array& force, Vec3Array& acceleration, IntegratorReport& report,
                   bool firstStage) {
  WEFT_PROFILE_ZONE("assembly");
  const std::int64_t start = FrameClock::nowNs();
  const Real energy = system.computeForces(x, v, t, force);
  report.assemblyMs += FrameClock::msSince(start);
  if (firstStage) report.potentialEnergy = energy;
  const std::vector<Real>& masses = system.masses();
  for (std::size_t i = 0; i < x.size(); ++i) acceleration[i] = force[i] / masses[i];
  for (Index pinned : system.prescribedVertices()) acceleration[pinned].setZero();
}

void resizeAll(Index n, std::initializer_list<Vec3Array*> arrays) {
  for (Vec3Array* array : arrays) array->resize(n);
}

}  // namespace

void ExplicitEuler::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                         IntegratorReport& report) {
  const Index n = system.vertexCount();
  resizeAll(n, {&m_force, &m_acceleration});
  accelerations(system, x, v, t, m_force, m_acceleration, report, true);
  for (Index i = 0; i < n; ++i) {
    x[i] += h * v[i];  // with the old velocity: this is what makes the method explicit
    v[i] += h * m_acceleration[i];
  }
  system.applyPrescribedMotion(t + h, x, v);
}

void SymplecticEuler::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                           IntegratorReport& report) {
  const Index n = system.vertexCount();
  resizeAll(n, {&m_force, &m_acceleration});
  accelerations(system, x, v, t, m_force, m_acceleration, report, true);
  for (Index i = 0; i < n; ++i) {
    v[i] += h * m_acceleration[i];
    x[i] += h * v[i];  // with the new velocity: symplectic for conservative forces
  }
  system.applyPrescribedMotion(t + h, x, v);
}

void Midpoint::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                    IntegratorReport& report) {
  const Index n = system.vertexCount();
  resizeAll(n, {&m_force, &m_acceleration, &m_midPosition, &m_midVelocity});
  accelerations(system, x, v, t, m_force, m_acceleration, report, true);
  for (Index i = 0; i < n; ++i) {
    m_midPosition[i] = x[i] + 0.5 * h * v[i];
    m_midVelocity[i] = v[i] + 0.5 * h * m_acceleration[i];
  }
  system.applyPrescribedMotion(t + 0.5 * h, m_midPosition, m_midVelocity);
  accelerations(system, m_midPosition, m_midVelocity, t + 0.5 * h, m_force, m_acceleration,
                report, false);
  for (Index i = 0; i < n; ++i) {
    x[i] += h * m_midVelocity[i];
    v[i] += h * m_acceleration[i];
  }
  system.applyPrescribedMotion(t + h, x, v);
}

void RungeKutta4::step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                       IntegratorReport& report) {
  const Index n = system.vertexCount();
  resizeAll(n, {&m_force, &m_stagePosition, &m_stageVelocity, &m_positionSum, &m_velocitySum,
                &m_acceleration});
  // Stage k evaluates the derivative (v_k, a_k) at (x + c_k h·dx_{k-1}, v + c_k h·dv_{k-1}).
  // The weighted sum 1/6 (k1 + 2 k2 + 2 k3 + k4) is accumulated as we go.
  const Real stageOffset[4] = {0.0, 0.5, 0.5, 1.0};
  const Real stageWeight[4] = {1.0 / 6.0, 2.0 / 6.0, 2.0 / 6.0, 1.0 / 6.0};
  for (Index i = 0; i < n; ++i) {
    m_stagePosition[i] = x[i];
    m_stageVelocity[i] = v[i];
    m_positionSum[i].setZero();
    m_velocitySum[i].setZero();
  }
  for (int stage = 0; stage < 4; ++stage) {
    const Real stageTime = t + stageOffset[stage] * h;
    system.applyPrescribedMotion(stageTime, m_stagePosition, m_stageVelocity);
    accelerations(system, m_stagePosition, m_stageVelocity, stageTime, m_force, m_acceleration,
                  report, stage == 0);
    const Real nextOffset = stage < 3 ? stageOffset[stage + 1] * h : 0.0;
    for (Index i = 0; i < n; ++i) {
      const Vec3 positionRate = m_stageVelocity[i];
      const Vec3 velocityRate = m_acceleration[i];
      m_positionSum[i] += stageWeight[stage] * positionRate;
      m_velocitySum[i] += stageWeight[stage] * velocityRate;
      m_stagePosition[i] = x[i] + nextOffset * positionRate;
      m_stageVelocity[i] = v[i] + nextOffset * velocityRate;
    }
  }
  for (Index i = 0; i < n; ++i) {
    x[i] += h * m_positionSum[i];
    v[i] += h * m_velocitySum[i];
  }
  system.applyPrescribedMotion(t + h, x, v);
}

}  // namespace weft
