// Stress scenes driven by pins:
//
//   5   a strip twisted by rotating its two pinned ends in opposite directions (±90° over 2 s,
//       then held for 1 s: half a turn in all, which stretches the strip's long edges by about
//       5 % if it stays flat, and makes it buckle and touch itself if it does not);
//   10  the pins of a hanging cloth teleported 10 m sideways in one frame: carried with them (a
//       teleport, SolverSettings::pinTeleportDistance), the cloth passes every condition from
//       the jump on; with the teleport rule off (dragged at 600 m/s), everything stays finite and
//       untangled, and the recovery is recorded (it depends on round-off).
#include "stress/StressSupport.h"

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

namespace weft::stress {
namespace {

constexpr Real kFrame = 1.0 / 60.0;

TEST(StressPins, StripTwistedByItsTwoPinnedEnds) {
  constexpr Index kColumns = 21, kRows = 5;
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 1.0;
  grid.height = 0.2;
  grid.origin = Vec3(-0.5, 1.0, 0.1);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  for (Index row = 0; row < kRows; ++row) settings.pinnedVertices.push_back(row * kColumns);
  for (Index row = 0; row < kRows; ++row) settings.pinnedVertices.push_back(row * kColumns + kColumns - 1);
  World world;
  const ClothId cloth = world.createCloth(model, settings).value();
  Vec3Array rest, targets(settings.pinnedVertices.size());
  for (Index vertex : settings.pinnedVertices) rest.push_back(model->restPositions()[vertex]);

  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  const Vec3 axisPoint(0, 1.0, 0);  // the strip's centre line runs along x through here
  for (int frame = 0; frame < 180; ++frame) {
    const Real t = (frame + 1) * kFrame;
    const Real s = std::min<Real>(t / 2.0, 1.0);
    const Real angle = 0.5 * std::numbers::pi * s * s * (3 - 2 * s);  // eased to 90°
    for (std::size_t k = 0; k < rest.size(); ++k) {
      const Real sign = k < kRows ? 1 : -1;  // the two ends turn in opposite directions
      const Eigen::AngleAxis<Real> turn(sign * angle, Vec3::UnitX());
      targets[k] = axisPoint + turn * (rest[k] - axisPoint);
    }
    ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
    if (!monitor.afterFrame(world.step(kFrame))) break;
  }
  // The ends did turn: the first end's corner at z = +0.1 is now below the axis.
  EXPECT_NEAR(world.positions(cloth).value()[settings.pinnedVertices[0]].y(), 0.9, 1e-9);
  monitor.expectPasses("twisted_strip");
}

// Scene 10: the pins of a hanging cotton sheet jump 10 m sideways in one frame.
//
// A jump of every pin farther than the cloth's size in one frame is a teleport
// (SolverSettings::pinTeleportDistance, default one cloth size): the cloth is carried with its
// pins and goes on as if nothing had happened (PinTeleportTest checks it against a sheet that
// stayed). Asserted here with the stress suite's conditions from the teleport frame on: one
// substep, strain within the limit in every frame, and the energy back within 1 % of m·g·height
// of its settled value within 2 s, for good.
//
// With the rule off (the second test) the pins move linearly across the frame, dragging the sheet
// at 600 m/s for 1/60 s and stopping dead. Automatic substepping keeps every pin within one mean
// edge length per substep (SolverSettings::maxPinTravelPerSubstep), so that frame takes 178
// substeps and ends at the strain limit; in the next frame the sheet, now at 600 m/s, crashes into
// the stopped pins. The dragging already crushes edges (the shortest at 14…49 % of its rest length
// at the drag frame's end in three traced runs), the crash crushes more, and whether every fold
// comes free depends on round-off: measured with bench/weft-teleport-perturb
// --pin-teleport-distance 0 (teleport distance changed by 0, 1e-12 … 3e-3 m, pin removal on and
// off: 24 runs), 6 of 24 keep folds crushed in self-contact for seconds (0.5…6 J above the
// settled energy, nearly all of it potential, against a 0.14 J band; hundreds of self-impacts a
// frame, and the self-collision passes stretch edges up to 0.85 after the limiter, which leaves
// no edge over; no capped solve, no frozen impact zone), and their strain from 2 s on is
// 0.103…0.134 with the energy not back. Counting the pins' change of velocity as travel (178 substeps for the crash too) made
// it worse (15 of 24). So with the rule off the recovery is recorded, not asserted; what holds in
// every perturbed run is asserted: finite, no intersecting pair, no capped solve, and the drag
// frame itself within the strain limit.
struct TeleportOutcome {
  Real dragFrameStrain = 0;
  Index teleportFrameSubsteps = 0, teleportedCloths = 0;
  Real baseline = 0, scale = 0, peakEnergy = 0, settledAt = -1, endX = 0;
};

// Runs the scene in `world` (empty), watched by `monitor` (made on it).
TeleportOutcome teleportScene(Real pinTeleportDistance, World& world, StressMonitor& monitor,
                              bool tightSolves = false) {
  constexpr Index kColumns = 13, kRows = 9;
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 0.6;
  grid.height = 0.4;
  grid.origin = Vec3(-0.3, 1.0, 0);
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  settings.solver.pinTeleportDistance = pinTeleportDistance;
  if (tightSolves) {  // every solve as tight as the hard substeps of the default
    settings.solver.cgTolerance = 1e-3;
    settings.solver.cgStopping = PcgStopping::RelativeResidual;
  }
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  const ClothId cloth = world.createCloth(model, settings).value();
  monitor.watch(cloth, *model);
  // Kinetic + potential (elastic and gravity); a sleeping cloth reports the potential of its
  // last stepped frame (StepStats::potentialEnergy), and the settled cloth is asleep here.
  auto energy = [&] { return world.stats().kineticEnergy + world.stats().potentialEnergy; };

  TeleportOutcome outcome;
  for (int frame = 0; frame < 90; ++frame) {
    if (!monitor.afterFrame(world.step(kFrame))) return outcome;
  }
  outcome.baseline = energy();
  // Energy scale of the test: lifting the cloth by its own height. The jump is sideways, so
  // gravity's share of the energy is the same before and after.
  outcome.scale = model->totalMass(settings.material.arealDensity) * 9.81 * grid.height;

  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (Vec3& target : targets) target.x() += 10.0;
  EXPECT_TRUE(world.setPinTargets(cloth, targets).ok());
  const bool dragged = pinTeleportDistance == 0;
  if (dragged) monitor.deferStrain();  // the drag and the crash stretch the cloth on purpose
  // Settled: within 1 % of m·g·height of the baseline from then on to the end of the run (3 s),
  // not merely passing through the band once.
  for (int frame = 0; frame < 180; ++frame) {
    const StepStatus status = world.step(kFrame);
    if (frame == 0) {
      outcome.dragFrameStrain = world.stats().maxStrain;
      outcome.teleportFrameSubsteps = world.stats().substeps;
      outcome.teleportedCloths = world.stats().teleportedCloths;
      std::printf("[stress] jump frame: %s (health: %s), %d substeps, %d cloths carried, max "
                  "strain %.4f\n", describe(status).c_str(), describe(world.stats().healthFailure),
                  int(world.stats().substeps), int(world.stats().teleportedCloths),
                  world.stats().maxStrain);
    }
    if (frame == 120 && dragged) monitor.measureStrainFromNow();
    if (!monitor.afterFrame(status)) break;
    outcome.peakEnergy = std::max(outcome.peakEnergy, energy() - outcome.baseline);
    const bool inBand = std::abs(energy() - outcome.baseline) <= 0.01 * outcome.scale;
    if (!inBand) outcome.settledAt = -1;
    if (inBand && outcome.settledAt < 0) outcome.settledAt = (frame + 1) * kFrame;
  }
  std::printf("[stress] energy %.4g J above the settled %.4g J at its peak; back within 1 %% of "
              "m·g·height (%.3g J) for good after %.3f s\n", outcome.peakEnergy, outcome.baseline,
              outcome.scale, outcome.settledAt);
  outcome.endX = world.positions(cloth).value()[0].x();
  return outcome;
}

TEST(StressPins, PinsTeleportedTenMetresCarryTheClothThere) {
  World world;
  StressMonitor monitor(world);
  const TeleportOutcome outcome = teleportScene(/*pinTeleportDistance=*/1, world, monitor);
  // The jump was a teleport: carried, one substep, nothing flung.
  EXPECT_EQ(outcome.teleportedCloths, 1u);
  EXPECT_EQ(outcome.teleportFrameSubsteps, 1);
  EXPECT_GT(outcome.endX, 9.0);
  // The settled cloth's energy is a real measurement (a sleeping cloth once reported no
  // potential energy, which made the baseline 0 J).
  EXPECT_GT(outcome.baseline, 0.1 * outcome.scale);
  EXPECT_GE(outcome.settledAt, 0) << "the energy is not back within 1 % of m·g·height at the end";
  EXPECT_LE(outcome.settledAt, 2.0) << "the energy took longer than 2 s to settle";
  monitor.expectPasses("teleported_pins", kCottonStrainLimit);  // strain in every frame
}

TEST(StressPins, PinsDraggedTenMetresInOneFrameStayFiniteAndUntangled) {
  World world;
  StressMonitor monitor(world);
  const TeleportOutcome outcome = teleportScene(/*pinTeleportDistance=*/0, world, monitor);
  EXPECT_EQ(outcome.teleportedCloths, 0u);
  EXPECT_EQ(outcome.teleportFrameSubsteps, 178);
  // The cloth followed its pins, and the drag frame itself stayed within the limit (0.1006 …
  // 0.1010 in all 48 runs of the harness, sleep on and off).
  EXPECT_GT(outcome.endX, 9.0);
  EXPECT_LE(outcome.dragFrameStrain, kCottonStrainLimit + kStrainTolerance);
  const bool settled = outcome.settledAt >= 0 && outcome.settledAt <= 2.0;
  constexpr const char* kFragile =
      "the crash into the stopped pins crushes folds that self-contact can hold for seconds; 6 of "
      "24 round-off perturbations fail (bench weft-teleport-perturb --pin-teleport-distance 0), so "
      "a pass here is a draw: keep the mark until the harness shows none failing";
  monitor.expectPasses("dragged_pins", kCottonStrainLimit,
                        {{StressMonitor::Condition::Strain, kFragile}});
  knownEngineFailure(settled, "energy back within 1 % of m·g·height within 2 s", kFragile);
}

}  // namespace
}  // namespace weft::stress
