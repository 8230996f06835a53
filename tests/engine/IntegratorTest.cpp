// Integrators against analytic results: the exact discrete solutions of backward Euler and BDF2
// on a linear oscillator, the stability limits of the explicit methods, and convergence orders
// on a nonlinear pendulum of stiff springs run through the full cloth path.
#include "integrators/Integrator.h"
#include "integrators/LinearOscillator.h"

#include <weft/engine/World.h>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

namespace weft {
namespace {

TEST(ImplicitEuler, MatchesTheExactDiscreteSolutionOfASpring) {
  // m = 1 kg, k = 100 N/m, h = 1/60 s: backward Euler maps (x, v) by B⁻¹ with
  // B = [1, −h; h ω², 1], whose eigenvalues have modulus (1 + ω²h²)^(−1/2) and phase atan(ωh).
  const Real mass = 1, stiffness = 100, h = 1.0 / 60.0;
  const Real omega = std::sqrt(stiffness / mass);
  SolverSettings settings;
  settings.cgTolerance = 1e-14;
  std::unique_ptr<Integrator> integrator = Integrator::create(IntegratorKind::ImplicitEuler, settings);
  LinearOscillator oscillator(mass, stiffness, 0.0);

  Eigen::Matrix2d exactStep;
  exactStep << 1, -h, h * omega * omega, 1;
  exactStep = exactStep.inverse().eval();

  Vec3Array x{Vec3(0.1, 0, 0)}, v{Vec3(0, 0, 0)};
  Eigen::Vector2d exact(0.1, 0.0);
  for (int step = 0; step < 120; ++step) {
    IntegratorReport report;
    integrator->step(oscillator, x, v, step * h, h, report);
    exact = exactStep * exact;
    ASSERT_NEAR(x[0].x(), exact(0), 1e-9 * 0.1) << "step " << step;
    ASSERT_NEAR(v[0].x(), exact(1), 1e-9 * 0.1 * omega) << "step " << step;
    EXPECT_TRUE(report.cgConverged);
  }

  // The amplification matrix read off the integrator itself.
  Eigen::Matrix2d map;
  for (int column = 0; column < 2; ++column) {
    Vec3Array xs{Vec3(column == 0, 0, 0)}, vs{Vec3(column == 1, 0, 0)};
    IntegratorReport report;
    integrator->reset();
    integrator->step(oscillator, xs, vs, 0, h, report);
    map(0, column) = xs[0].x();
    map(1, column) = vs[0].x();
  }
  const std::complex<Real> eigenvalue = map.eigenvalues()(0);
  EXPECT_NEAR(std::abs(eigenvalue), 1 / std::sqrt(1 + omega * omega * h * h), 1e-9);
  EXPECT_NEAR(std::abs(std::arg(eigenvalue)), std::atan(omega * h), 1e-9);
}

TEST(Bdf2, MatchesTheExactDiscreteSolutionOfASpring) {
  // m = 1 kg, k = 100 N/m, h = 1/60 s. The first step is backward Euler; every later one solves
  // x₊ = x̂ + βh v₊, v₊ = v̂ − βh ω² x₊ with x̂ = (4xₙ − xₙ₋₁)/3, v̂ = (4vₙ − vₙ₋₁)/3, β = 2/3.
  const Real mass = 1, stiffness = 100, h = 1.0 / 60.0;
  const Real omega2 = stiffness / mass;
  SolverSettings settings;
  settings.cgTolerance = 1e-14;
  settings.cgStopping = PcgStopping::RelativeResidual;
  std::unique_ptr<Integrator> integrator = Integrator::create(IntegratorKind::Bdf2, settings);
  ASSERT_EQ(integrator->kind(), IntegratorKind::Bdf2);
  ASSERT_EQ(integrator->order(), 2);
  LinearOscillator oscillator(mass, stiffness, 0.0);
  Vec3Array x{Vec3(0.1, 0, 0)}, v{Vec3(0, 0, 0)};
  Real px = 0.1, pv = 0;  // the exact discrete solution, by hand
  Real previousX = 0, previousV = 0;
  for (int step = 0; step < 240; ++step) {
    IntegratorReport report;
    integrator->step(oscillator, x, v, step * h, h, report);
    Real nx, nv;
    if (step == 0) {
      nv = (pv - h * omega2 * px) / (1 + h * h * omega2);
      nx = px + h * nv;
    } else {
      const Real beta = 2.0 / 3.0;
      const Real hatX = (4 * px - previousX) / 3, hatV = (4 * pv - previousV) / 3;
      nv = (hatV - beta * h * omega2 * hatX) / (1 + beta * beta * h * h * omega2);
      nx = hatX + beta * h * nv;
    }
    previousX = px, previousV = pv;
    px = nx, pv = nv;
    ASSERT_NEAR(x[0].x(), px, 1e-10) << "step " << step;
    ASSERT_NEAR(v[0].x(), pv, 1e-9) << "step " << step;
  }
}

TEST(Bdf2, ChangesStepAndRestartsAfterAGapOrAReset) {
  // A varying step (ratio up to 2) keeps the variable-step BDF2 on the spring's exact solution to
  // second order, and a step that does not follow on in time starts again with backward Euler:
  // stepping after a gap equals a fresh integrator's first step from the same state.
  const Real stiffness = 100;
  SolverSettings settings;
  settings.cgTolerance = 1e-14;
  settings.cgStopping = PcgStopping::RelativeResidual;
  LinearOscillator oscillator(1, stiffness, 0.0);
  // The largest error over the times both step sequences reach (every 1/30 s for 1 s): one time
  // alone can sit where the error's components cancel.
  const auto largestError = [&](int refinement) {
    std::unique_ptr<Integrator> integrator = Integrator::create(IntegratorKind::Bdf2, settings);
    Vec3Array x{Vec3(0.1, 0, 0)}, v{Vec3::Zero()};
    Real t = 0, largest = 0;
    for (int step = 0; step < 90 * refinement; ++step) {
      const Real h = (step % 3 == 0 ? 2.0 : 1.0) / (120.0 * refinement);  // ratios 2 and ½
      IntegratorReport report;
      integrator->step(oscillator, x, v, t, h, report);
      t += h;
      if ((step + 1) % (3 * refinement) == 0) {
        largest = std::max(largest, std::abs(x[0].x() - 0.1 * std::cos(std::sqrt(stiffness) * t)));
      }
    }
    return largest;
  };
  EXPECT_NEAR(std::log2(largestError(1) / largestError(2)), 2.0, 0.3);

  std::unique_ptr<Integrator> continued = Integrator::create(IntegratorKind::Bdf2, settings);
  Vec3Array x{Vec3(0.1, 0, 0)}, v{Vec3::Zero()};
  IntegratorReport report;
  for (int step = 0; step < 5; ++step) continued->step(oscillator, x, v, step / 60.0, 1 / 60.0, report);
  Vec3Array freshX = x, freshV = v;
  continued->step(oscillator, x, v, 1.0, 1 / 60.0, report);  // 0.92 s later than the last step
  std::unique_ptr<Integrator> fresh = Integrator::create(IntegratorKind::Bdf2, settings);
  fresh->step(oscillator, freshX, freshV, 1.0, 1 / 60.0, report);
  // Up to the solve's round-off (the continued integrator starts its PCG from its last Δv).
  EXPECT_NEAR((x[0] - freshX[0]).norm(), 0, 1e-15);
  EXPECT_NEAR((v[0] - freshV[0]).norm(), 0, 1e-13);
}

TEST(StableStepLimit, MatchesKnownStabilityBoundaries) {
  const Real omega = 50;
  // Symplectic Euler on an undamped oscillator: stable exactly for h ω < 2.
  EXPECT_NEAR(stableStepLimit(IntegratorKind::SymplecticEuler, omega, 0, 1e-9) * omega, 2.0, 1e-3);
  // RK4 on the imaginary axis: stable for h ω ≤ 2√2.
  EXPECT_NEAR(stableStepLimit(IntegratorKind::RungeKutta4, omega, 0, 1e-9) * omega,
              2 * std::sqrt(2.0), 1e-3);
  // Explicit Euler grows by √(1 + ω²h²) per step: within 1e-6 growth only for h ω ≤ √(2e-6).
  EXPECT_NEAR(stableStepLimit(IntegratorKind::ExplicitEuler, omega, 0, 1e-6) * omega,
              std::sqrt((1 + 1e-6) * (1 + 1e-6) - 1), 1e-6);
  // Damping widens explicit Euler's region: stable for h < 2ζ/ω = c/ω² when underdamped.
  const Real dampingRate = 10;  // c = 2ζω with ζ = 0.1
  EXPECT_NEAR(stableStepLimit(IntegratorKind::ExplicitEuler, omega, dampingRate, 1e-12),
              dampingRate / (omega * omega), 1e-6);
  EXPECT_TRUE(std::isinf(stableStepLimit(IntegratorKind::ImplicitEuler, omega, 0, 0)));
  EXPECT_TRUE(std::isinf(stableStepLimit(IntegratorKind::Bdf2, omega, 0, 0)));
}

// A pendulum: one free vertex hanging from two pinned ones by stiff springs (mass-spring model on
// one triangle), released 30° from the vertical. Smooth and nonlinear.
struct Pendulum {
  World world;
  ClothId cloth;

  explicit Pendulum(IntegratorKind integrator, int newtonIterations = 0) {
    const Real length = 1.0, angle = 30.0 * std::numbers::pi / 180.0;
    TriangleMesh mesh;
    mesh.positions = {Vec3(-0.5, 0, 0), Vec3(0.5, 0, 0),
                      Vec3(0, -length * std::cos(angle), length * std::sin(angle))};
    mesh.indices = {0, 1, 2};
    auto model = std::make_shared<ClothModel>(ClothModel::fromMesh(mesh).value());
    ClothSettings settings;
    settings.forceModel = ForceModel::MassSpring;
    settings.material.airDrag = 0;
    settings.springs = MassSpringMaterial{};
    settings.springs.structuralStiffness = 500;  // N/m: spring modes near 30 rad/s, swing near 3
    settings.springs.structuralDamping = 0;
    settings.material.arealDensity = 3.0 / model->totalArea();  // 1 kg per vertex
    settings.pinnedVertices = {0, 1};
    settings.solver.integrator = integrator;
    settings.solver.substeps = 1;
    settings.solver.cgTolerance = 1e-13;
    settings.solver.newtonIterations = newtonIterations;
    cloth = world.createCloth(model, settings).value();
  }

  Vec3 positionAfter(Real duration, int steps) {
    for (int k = 0; k < steps; ++k) world.step(duration / steps);
    return world.positions(cloth).value()[2];
  }

  // Position of the swinging vertex at ten evenly spaced times over the duration.
  std::vector<Vec3> trajectory(Real duration, int steps) {
    std::vector<Vec3> samples;
    for (int k = 0; k < steps; ++k) {
      world.step(duration / steps);
      if ((k + 1) % (steps / 10) == 0) samples.push_back(world.positions(cloth).value()[2]);
    }
    return samples;
  }
};

struct OrderCase {
  IntegratorKind integrator;
  int newtonIterations;
  Real expectedOrder;
  std::array<int, 4> steps;
};

class IntegratorOrder : public ::testing::TestWithParam<OrderCase> {};

TEST_P(IntegratorOrder, ConvergesAtItsOrderOnAStiffSpringPendulum) {
  const OrderCase& c = GetParam();
  // The error is the largest distance to a fine RK4 reference over ten sample times: a single
  // end time can sit where components of the error happen to cancel, which hides the order.
  const Real duration = 0.5;
  const std::vector<Vec3> reference = Pendulum(IntegratorKind::RungeKutta4).trajectory(duration, 32000);
  std::vector<Real> logStep, logError;
  for (int steps : c.steps) {
    const std::vector<Vec3> samples =
        Pendulum(c.integrator, c.newtonIterations).trajectory(duration, steps);
    Real error = 0;
    for (std::size_t k = 0; k < samples.size(); ++k) {
      error = std::max(error, (samples[k] - reference[k]).norm());
    }
    ASSERT_TRUE(std::isfinite(error));
    logStep.push_back(std::log(duration / steps));
    logError.push_back(std::log(error));
  }
  // Least-squares slope of log(error) against log(h).
  const Real n = Real(logStep.size());
  Real sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < logStep.size(); ++k) {
    sx += logStep[k];
    sy += logError[k];
    sxx += logStep[k] * logStep[k];
    sxy += logStep[k] * logError[k];
  }
  const Real slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  EXPECT_NEAR(slope, c.expectedOrder, 0.3) << integratorName(c.integrator);
}

INSTANTIATE_TEST_SUITE_P(
    Methods, IntegratorOrder,
    ::testing::Values(
        OrderCase{IntegratorKind::ExplicitEuler, 0, 1.0, {800, 1600, 3200, 6400}},
        OrderCase{IntegratorKind::SymplecticEuler, 0, 1.0, {400, 800, 1600, 3200}},
        OrderCase{IntegratorKind::Midpoint, 0, 2.0, {200, 400, 800, 1600}},
        OrderCase{IntegratorKind::RungeKutta4, 0, 4.0, {100, 200, 400, 800}},
        OrderCase{IntegratorKind::ImplicitEuler, 0, 1.0, {800, 1600, 3200, 6400}},
        OrderCase{IntegratorKind::ImplicitEuler, 2, 1.0, {800, 1600, 3200, 6400}},
        OrderCase{IntegratorKind::Bdf2, 0, 2.0, {200, 400, 800, 1600}},
        OrderCase{IntegratorKind::Bdf2, 2, 2.0, {200, 400, 800, 1600}}),
    [](const ::testing::TestParamInfo<OrderCase>& info) {
      return std::string(info.param.integrator == IntegratorKind::ExplicitEuler     ? "ExplicitEuler"
                         : info.param.integrator == IntegratorKind::SymplecticEuler ? "SymplecticEuler"
                         : info.param.integrator == IntegratorKind::Midpoint        ? "Midpoint"
                         : info.param.integrator == IntegratorKind::RungeKutta4     ? "RungeKutta4"
                         : info.param.integrator == IntegratorKind::Bdf2            ? "Bdf2"
                                                                                    : "ImplicitEuler") +
             (info.param.newtonIterations ? "Newton" : "");
    });

TEST(ImplicitEuler, NewtonIterationsApproachTheExactBackwardEulerStep) {
  // One large step of the pendulum: the BW98 single linearisation and the Newton-refined step
  // differ, and more iterations change the result less and less (convergence of Newton).
  const Real h = 0.05;
  Vec3 previous = Pendulum(IntegratorKind::ImplicitEuler, 0).positionAfter(h, 1);
  std::vector<Real> changes;
  for (int iterations = 1; iterations <= 4; ++iterations) {
    const Vec3 position = Pendulum(IntegratorKind::ImplicitEuler, iterations).positionAfter(h, 1);
    changes.push_back((position - previous).norm());
    previous = position;
  }
  EXPECT_GT(changes[0], 1e-6);               // Newton does something after BW's step
  EXPECT_LT(changes[1], 0.01 * changes[0]);  // and converges fast (quadratically)
  EXPECT_LT(changes[3], 1e-12);              // down to round-off
}

}  // namespace
}  // namespace weft
