#include "integrators/Integrator.h"

#include "integrators/Bdf2.h"
#include "integrators/ExplicitIntegrators.h"
#include "integrators/ImplicitEuler.h"
#include "integrators/LinearOscillator.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace weft {

const char* integratorName(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::ExplicitEuler: return "explicit-euler";
    case IntegratorKind::SymplecticEuler: return "symplectic-euler";
    case IntegratorKind::Midpoint: return "midpoint";
    case IntegratorKind::RungeKutta4: return "rk4";
    case IntegratorKind::ImplicitEuler: return "implicit-euler";
    case IntegratorKind::Bdf2: return "bdf2";
  }
  return "unknown";
}

std::unique_ptr<Integrator> Integrator::create(IntegratorKind kind, const SolverSettings& settings) {
  switch (kind) {
    case IntegratorKind::ExplicitEuler: return std::make_unique<ExplicitEuler>();
    case IntegratorKind::SymplecticEuler: return std::make_unique<SymplecticEuler>();
    case IntegratorKind::Midpoint: return std::make_unique<Midpoint>();
    case IntegratorKind::RungeKutta4: return std::make_unique<RungeKutta4>();
    case IntegratorKind::ImplicitEuler: return std::make_unique<ImplicitEuler>(settings);
    case IntegratorKind::Bdf2: return std::make_unique<Bdf2>(settings);
  }
  return nullptr;
}

namespace {

// Spectral radius of the method's one-step map on the oscillator ẍ = −ω² x − c ẋ (m = 1),
// read off by stepping the unit initial conditions (x, v) = (1, 0) and (0, 1).
Real amplification(Integrator& integrator, LinearOscillator& oscillator, Real h) {
  Eigen::Matrix2d map;
  for (int column = 0; column < 2; ++column) {
    Vec3Array x{Vec3(column == 0 ? 1.0 : 0.0, 0, 0)};
    Vec3Array v{Vec3(column == 1 ? 1.0 : 0.0, 0, 0)};
    IntegratorReport report;
    integrator.step(oscillator, x, v, 0.0, h, report);
    map(0, column) = x[0].x();
    map(1, column) = v[0].x();
  }
  return map.eigenvalues().cwiseAbs().maxCoeff();
}

}  // namespace

Real stableStepLimit(IntegratorKind kind, Real omega, Real dampingRate, Real growthPerStep) {
  // Both implicit methods are A-stable: no step makes a damped linear mode grow.
  if (isImplicit(kind)) return std::numeric_limits<Real>::infinity();
  if (!(omega > 0)) return std::numeric_limits<Real>::infinity();
  std::unique_ptr<Integrator> integrator = Integrator::create(kind, SolverSettings{});
  LinearOscillator oscillator(1.0, omega * omega, dampingRate);
  const Real allowed = 1.0 + growthPerStep;
  // Every explicit method here is stable (or within the growth allowance) for small enough h
  // and unstable beyond some h ω of order one: bracket the boundary, then bisect in log h.
  Real stable = 1e-9 / omega;
  if (amplification(*integrator, oscillator, stable) > allowed) return 0.0;
  Real unstable = 10.0 / omega;
  if (amplification(*integrator, oscillator, unstable) <= allowed) return unstable;
  for (int iteration = 0; iteration < 60; ++iteration) {
    const Real middle = std::sqrt(stable * unstable);
    (amplification(*integrator, oscillator, middle) <= allowed ? stable : unstable) = middle;
  }
  return stable;
}

}  // namespace weft
