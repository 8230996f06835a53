// The default dynamics: SolverSettings{} (its integrator, its tolerance, one substep of 1/60 s) on
// a pendulum against the closed form and on a free drape against a converged run, with the
// damping and the error the method's theory gives, whatever the default integrator is.
#include "ContactTestSupport.h"

#include <weft/engine/World.h>
#include <weft/scenes/FreeDrape.h>
#include <weft/scenes/Pendulum.h>

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace weft {
namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;

TEST(DefaultDynamics, APendulumKeepsTheAmplitudeAndPeriodItsMethodGives) {
  // The closed form of the method on the linear swing θ'' = −ω² θ: its growth factor ρ per step
  // (PendulumScene::growthFactor), so a period of 2π h / arg ρ and |ρ| kept per step. Bounds: the
  // 5° swing's nonlinearity moves ω by θ₀²/16 = 0.05 %, the springs' stretch (m g / 2k ≈ 5 µm on
  // 1 m) by less. The single linearisation per step (the default) must not change the method:
  // the loss per period within a tenth of the predicted loss (plus 0.1 % for a method that
  // predicts almost none; BDF2 needs a Newton iteration for that, bench/results/
  // error-time-curtain.md) and the period within 0.5 %.
  const SolverSettings defaults;
  ASSERT_EQ(defaults.substeps, 0u);
  ASSERT_EQ(defaults.maxImplicitStep, 1.0 / 60.0);  // one substep per 1/60 s frame
  PendulumScene scene = PendulumScene::create(PendulumSettings{}).value();
  const Real h = PendulumScene::kFrameDt, omega = scene.frequency();
  const std::complex<Real> rho = PendulumScene::growthFactor(defaults.integrator, omega * h);
  const Real period = 2 * kPi * h / std::arg(rho);
  const Real predictedLoss = 1 - std::pow(std::abs(rho), period / h);

  std::vector<Real> angles{scene.angle()};
  for (int frame = 0; frame < int(6.5 * period / h); ++frame) {
    ASSERT_EQ(scene.stepFrame(), StepStatus::Ok);
    angles.push_back(scene.angle());
  }
  std::vector<Real> peaks, crossings;
  for (std::size_t k = 1; k + 1 < angles.size(); ++k) {
    const Real a = angles[k - 1], b = angles[k], c = angles[k + 1];
    if (b > a && b >= c) peaks.push_back(b - 0.125 * (a - c) * (a - c) / (a - 2 * b + c));
    if (a < 0 && b >= 0) crossings.push_back(h * (Real(k - 1) + a / (a - b)));
  }
  ASSERT_GE(peaks.size(), 5u);
  const Real keptPerPeriod = std::pow(peaks.back() / peaks.front(), 1.0 / Real(peaks.size() - 1));
  EXPECT_NEAR(1 - keptPerPeriod, predictedLoss, 0.1 * predictedLoss + 1e-3)
      << integratorName(defaults.integrator) << ": " << peaks.size() << " turning points";
  const Real measuredPeriod = (crossings.back() - crossings.front()) / Real(crossings.size() - 1);
  EXPECT_NEAR(measuredPeriod, period, 0.005 * period);
  // And the closed-form period of the pendulum itself, 2π √(L/g), within the method's phase
  // error (BE: arctan(ωh)/ωh, 0.09 % at 1/60 s) and the nonlinearity's 0.05 %.
  EXPECT_NEAR(measuredPeriod, 2 * kPi / omega, 0.005 * period);
}

// The largest RMS distance (m) between two runs over samples every 0.1 s of 2 s.
struct DrapeRun {
  std::vector<Vec3Array> samples;
};

DrapeRun runDrape(const SolverSettings& solver) {
  FreeDrapeSettings settings;
  settings.solver = solver;
  FreeDrapeScene scene = FreeDrapeScene::create(settings).value();
  DrapeRun run;
  for (int frame = 1; frame <= 120; ++frame) {
    const StepStatus status = scene.stepFrame();
    EXPECT_FALSE(hasFlag(status, StepStatus::RolledBack) || hasFlag(status, StepStatus::Unstable));
    if (frame % 6 == 0) run.samples.emplace_back(scene.positions().begin(), scene.positions().end());
  }
  return run;
}

Real distance(const DrapeRun& a, const DrapeRun& b) {
  Real largest = 0;
  for (std::size_t k = 0; k < a.samples.size(); ++k) {
    Real sum = 0;
    for (std::size_t i = 0; i < a.samples[k].size(); ++i) {
      sum += (a.samples[k][i] - b.samples[k][i]).squaredNorm();
    }
    largest = std::max(largest, std::sqrt(sum / Real(a.samples[k].size())));
  }
  return largest;
}

TEST(DefaultDynamics, AFreeDrapeIsAsFarFromTheConvergedMotionAsItsMethodsOrderGives) {
  // A 1 m sheet released 30° from hanging (scenes/FreeDrape.h), 2 s of smooth swing. Converged:
  // BDF2 with two Newton iterations at 1/480 s, PCG to 1e-10, whose distance to the same at
  // 1/240 s (a bound on its own error) must be 10× below the smallest error measured.
  // The defaults at 1/60, 1/120 and 1/240 s (their own tolerance) must converge towards it at the
  // order of the default method p (1 for backward Euler, 2 for BDF2): error ratios of 2^p per
  // halving, within 0.3 in the observed order (the step is not asymptotically small for the
  // sheet's stiff modes), and the default step's error must be its Richardson estimate
  // 2^p / (2^p − 1) · |x_h − x_{h/2}| within a quarter.
  SolverSettings converged;
  converged.integrator = IntegratorKind::Bdf2;
  converged.newtonIterations = 2;
  converged.cgTolerance = 1e-10;
  converged.cgStopping = PcgStopping::RelativeResidual;
  converged.tightCgTolerance = 0;
  converged.cgMaxIterations = 5000;
  converged.substeps = 8;
  const DrapeRun reference = runDrape(converged);
  converged.substeps = 4;
  const Real referenceError = distance(runDrape(converged), reference);

  const SolverSettings defaults;
  const Real order = defaults.integrator == IntegratorKind::Bdf2 ? 2 : 1;
  std::vector<DrapeRun> runs;
  std::vector<Real> errors;
  for (Index substeps : {1, 2, 4}) {
    SolverSettings solver = defaults;
    solver.substeps = substeps;
    runs.push_back(runDrape(solver));
    errors.push_back(distance(runs.back(), reference));
  }
  ASSERT_LT(referenceError, 0.1 * errors.back()) << "the converged run is not converged";
  EXPECT_NEAR(std::log2(errors[0] / errors[1]), order, 0.3) << errors[0] << " m, " << errors[1] << " m";
  EXPECT_NEAR(std::log2(errors[1] / errors[2]), order, 0.3) << errors[1] << " m, " << errors[2] << " m";
  const Real richardson = std::pow(2.0, order) / (std::pow(2.0, order) - 1) * distance(runs[0], runs[1]);
  EXPECT_NEAR(errors[0], richardson, 0.25 * errors[0]);
}

// A 1 m sheet of the default solver with no gravity, drag, contact or self-collision, set
// moving at about 1 m/s (a random field, seeded) with zero momentum and zero angular momentum
// (equal masses).
struct FreeSheet {
  static constexpr Index kSide = 21;
  World world;
  ClothId cloth;

  explicit FreeSheet(const SolverSettings& solver = {}) : world(freeWorld()) {
    const std::shared_ptr<const ClothModel> model = test::horizontalSquare(kSide, 1.0, 0.0);
    ClothSettings settings;
    settings.solver = solver;
    settings.selfCollision = false;
    settings.material.airDrag = 0;
    settings.vertexMasses.assign(kSide * kSide, 0.15 / Real((kSide - 1) * (kSide - 1)));
    cloth = world.createCloth(model, settings).value();
    const std::span<const Vec3> start = world.positions(cloth).value();
    const Vec3Array positions(start.begin(), start.end());
    Vec3Array velocities(positions.size());
    std::mt19937 random(3);
    std::normal_distribution<Real> normal(0, 0.5);
    for (Vec3& v : velocities) v = Vec3(normal(random), 0.2 * normal(random), normal(random));
    // Take out the mean velocity, then the rigid spin ω = I⁻¹ L about the centre.
    Vec3 mean = Vec3::Zero();
    for (const Vec3& v : velocities) mean += v;
    mean /= Real(velocities.size());
    for (Vec3& v : velocities) v -= mean;
    const Vec3 spin = spinRate(positions, velocities);
    const Vec3 centre = centreOf(positions);
    for (std::size_t i = 0; i < velocities.size(); ++i) {
      velocities[i] -= spin.cross(positions[i] - centre);
    }
    EXPECT_TRUE(world.setState(cloth, positions, velocities).ok());
  }

  static World freeWorld() {
    WorldSettings settings;
    settings.gravity = Vec3::Zero();
    return World(settings);
  }
  static Vec3 centreOf(std::span<const Vec3> points) {
    Vec3 sum = Vec3::Zero();
    for (const Vec3& p : points) sum += p;
    return sum / Real(points.size());
  }
  // rad/s: the rigid rotation with the same angular momentum about the centre (equal masses).
  static Vec3 spinRate(std::span<const Vec3> x, std::span<const Vec3> v) {
    const Vec3 centre = centreOf(x);
    Vec3 momentum = Vec3::Zero();
    Mat3 inertia = Mat3::Zero();
    for (std::size_t i = 0; i < x.size(); ++i) {
      const Vec3 r = x[i] - centre;
      momentum += r.cross(v[i]);
      inertia += r.squaredNorm() * Mat3::Identity() - r * r.transpose();
    }
    return inertia.ldlt().solve(momentum);
  }
  Vec3 spinRate() const {
    return spinRate(world.positions(cloth).value(), world.velocities(cloth).value());
  }
  void run(int frames) {
    for (int frame = 0; frame < frames; ++frame) ASSERT_EQ(world.step(1.0 / 60), StepStatus::Ok);
  }
};

TEST(DefaultDynamics, AFreeSheetKeepsItsLinearMomentum) {
  // Internal forces sum to zero, and so do the rows of their Jacobians: backward Euler, solved
  // exactly, changes a free cloth's momentum by nothing, and an inexact solve must not either.
  // The free sheet keeps its centre of mass still to 1 µm/s (rounding is some 1e-14 m/s).
  FreeSheet sheet;
  sheet.run(30);
  const Vec3 centre = FreeSheet::centreOf(sheet.world.velocities(sheet.cloth).value());
  EXPECT_LT(centre.norm(), 1e-6) << "the centre of mass drifts at " << centre.norm() << " m/s";
}

TEST(DefaultDynamics, AFreeSheetGainsNoMoreSpinFromItsSolverThanFromItsMethod) {
  // Internal forces exert no net torque, but backward Euler does not keep the angular momentum
  // exactly: L changes by h Σ xₙ × f(xₙ₊₁) per step, O(h²). The PCG's early stop must not add a
  // spin of its own larger than that: after 2 s the free sheet at the default tolerance turns
  // at most twice as fast as the same sheet solved to a relative residual of 1e-10 (the method's
  // own spin; the early stop's share is then at most as large).
  SolverSettings converged;
  converged.cgTolerance = 1e-10;
  converged.cgStopping = PcgStopping::RelativeResidual;
  FreeSheet sheet, reference(converged);
  sheet.run(120);
  reference.run(120);
  const Real spin = sheet.spinRate().norm(), methodSpin = reference.spinRate().norm();
  EXPECT_LE(spin, 2 * methodSpin) << "the default solve turns the sheet at " << spin
                                  << " rad/s, the converged one at " << methodSpin << " rad/s";
}

}  // namespace
}  // namespace weft
