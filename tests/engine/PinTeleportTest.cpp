// Pins that jump far in one frame (stress scene 10, issue 9), and the energy a sleeping cloth
// reports:
//   - when every pin jumps farther than SolverSettings::pinTeleportDistance cloth sizes, the
//     frame is a teleport: the cloth is carried by the pins' jump, velocities unchanged, and
//     continues as if nothing had happened; one pin yanked alone is no teleport;
//   - the carry is the pins' best-fit rigid motion: pins that jump and turn (a respawn facing the
//     other way) carry the cloth turned, and it goes on like a sheet that stayed, seen in the
//     turned frame; collinear pins and a single pin carry what they determine;
//   - pins turned in place as one body by more than SolverSettings::pinTeleportAngle (a row turned
//     end for end about its middle, where the distance rule cannot see it) carry the cloth too;
//     smaller turns and non-rigid pin motions are dragged;
//   - otherwise (or with the teleport off), automatic substepping keeps every pin within one mean
//     edge length per substep, so a cloth whose pins jump 10 m is hauled after them within its
//     strain limit in that frame (in one substep the limiter stopped at its iteration cap with
//     almost every edge far over);
//   - targets that stretch an edge between two pins past what a frame may end with are refused;
//   - a sleeping cloth reports the potential energy of its last stepped frame, not 0 J (the stress
//     scene measured its settled energy on a sleeping cloth and got a baseline of 0 J).
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

namespace weft {
namespace {

constexpr Real kFrameDt = 1.0 / 60;
constexpr Index kColumns = 9, kRows = 7;
constexpr Real kWidth = 0.4, kHeight = 0.3;

std::shared_ptr<const ClothModel> sheet() {
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = kWidth;
  grid.height = kHeight;
  grid.origin = Vec3(-kWidth / 2, 1.0, 0.0);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

// Cotton (strain limit 0.10) hanging from its top row.
ClothSettings hangingCotton() {
  ClothSettings settings;
  settings.material = cottonFabric();
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  return settings;
}

Real meanEdgeLength(const ClothModel& model) {
  Real sum = 0;
  for (const Edge& edge : model.edges()) sum += edge.restLength;
  return sum / Real(model.edges().size());
}

// Cotton hanging from its top row, with the teleport rule off: pins drag the cloth however far
// they jump.
ClothSettings draggedCotton() {
  ClothSettings settings = hangingCotton();
  settings.solver.pinTeleportDistance = 0;
  return settings;
}

TEST(PinTeleport, PlannedSubstepsKeepEveryPinWithinAnEdge) {
  const auto model = sheet();
  World world;
  const ClothId cloth = world.createCloth(model, draggedCotton()).value();
  // Still pins: the stability rule alone (one implicit substep per 1/60 s frame).
  EXPECT_EQ(world.plannedSubsteps(cloth, kFrameDt).value(), 1);
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (Vec3& target : targets) target.x() += 10.0;
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
  const Index substeps = world.plannedSubsteps(cloth, kFrameDt).value();
  EXPECT_EQ(substeps, Index(std::ceil(10.0 / meanEdgeLength(*model) * (1 - 1e-9))));
  // With the default teleport rule the same jump carries the cloth: its pins do not move relative
  // to it, so the stability rule alone.
  const ClothId teleported = world.createCloth(model, hangingCotton()).value();
  ASSERT_TRUE(world.setPinTargets(teleported, targets).ok());
  EXPECT_EQ(world.plannedSubsteps(teleported, kFrameDt).value(), 1);
  // Fixed substeps are the caller's choice and stay as given.
  ClothSettings fixed = draggedCotton();
  fixed.solver.substeps = 2;
  const ClothId fixedCloth = world.createCloth(model, fixed).value();
  ASSERT_TRUE(world.setPinTargets(fixedCloth, targets).ok());
  EXPECT_EQ(world.plannedSubsteps(fixedCloth, kFrameDt).value(), 2);
  // The allowed travel is a setting: 4 edges a substep need a quarter of the substeps (rounded
  // up), 0 turns the rule off.
  ClothSettings looser = draggedCotton();
  looser.solver.maxPinTravelPerSubstep = 4;
  const ClothId looserCloth = world.createCloth(model, looser).value();
  ASSERT_TRUE(world.setPinTargets(looserCloth, targets).ok());
  EXPECT_EQ(world.plannedSubsteps(looserCloth, kFrameDt).value(),
            Index(std::ceil(10.0 / (4 * meanEdgeLength(*model)) * (1 - 1e-9))));
  ClothSettings off = draggedCotton();
  off.solver.maxPinTravelPerSubstep = 0;
  const ClothId offCloth = world.createCloth(model, off).value();
  ASSERT_TRUE(world.setPinTargets(offCloth, targets).ok());
  EXPECT_EQ(world.plannedSubsteps(offCloth, kFrameDt).value(), 1);
}

TEST(PinTeleport, ANegativeOrNonFinitePinTravelIsRefusedByName) {
  World world;
  for (Real bad : {Real(-1), std::nan("")}) {
    ClothSettings settings = hangingCotton();
    settings.solver.maxPinTravelPerSubstep = bad;
    const Result<ClothId> cloth = world.createCloth(sheet(), settings);
    ASSERT_FALSE(cloth.ok());
    EXPECT_NE(cloth.error().message.find("maxPinTravelPerSubstep"), std::string::npos)
        << cloth.error().message;
  }
  EXPECT_EQ(world.clothCount(), 0u);
}

TEST(PinTeleport, ClothDraggedTenMetresFollowsWithinItsStrainLimit) {
  // Self-collision off: this is about the solve and the strain limit following the pins. Awake
  // (sleep off), so the cloth starts the jump with the small motions of a hanging sheet. The
  // teleport rule is off, so the pins drag the cloth.
  ClothSettings settings = draggedCotton();
  settings.selfCollision = false;
  settings.sleep.enabled = false;
  World world;
  const ClothId cloth = world.createCloth(sheet(), settings).value();
  for (int frame = 0; frame < 60; ++frame) world.step(kFrameDt);
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (Vec3& target : targets) target.x() += 10.0;
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
  const StepStatus status = world.step(kFrameDt);
  const StepStats& stats = world.stats();
  std::printf("[pin teleport] %d substeps, max strain %.4f, edges the limiter left over (all "
              "substeps) %llu, %s\n",
              int(stats.substeps), stats.maxStrain,
              static_cast<unsigned long long>(stats.strainLimitEdgesOver), describe(status).c_str());
  // Measured before the substepping rule (one substep): strain 17.9 on stress scene 10's sheet,
  // with the limiter at its cap and almost every edge over.
  EXPECT_LE(stats.maxStrain, settings.material.strainLimit + 0.01);
  EXPECT_FALSE(hasFlag(status, StepStatus::RolledBack));
  // Every vertex came along: the sheet hangs 10 m further on, within its own size of the pins.
  for (const Vec3& x : world.positions(cloth).value()) {
    EXPECT_GT(x.x(), 10.0 - kWidth / 2 - kHeight);
    EXPECT_LT(x.x(), 10.0 + kWidth / 2 + kHeight);
  }
}

TEST(PinTeleport, TheJumpAndTheCrashAfterItGiveTheSameBitsOnOneAndTwoThreads) {
  // Self-collision on: the substeps of the jump and the crash into the stopped pins in the next
  // frames run every parallel stage (solve, limiter, swept tests, impact zones).
  auto run = [](int threads) {
    WorldSettings worldSettings;
    worldSettings.threadCount = threads;
    World world(worldSettings);
    const ClothId cloth = world.createCloth(sheet(), draggedCotton()).value();
    for (int frame = 0; frame < 30; ++frame) world.step(kFrameDt);
    std::vector<Vec3> targets = world.pinTargets(cloth).value();
    for (Vec3& target : targets) target.x() += 10.0;
    EXPECT_TRUE(world.setPinTargets(cloth, targets).ok());
    for (int frame = 0; frame < 10; ++frame) world.step(kFrameDt);
    const std::span<const Vec3> x = world.positions(cloth).value();
    return std::vector<Vec3>(x.begin(), x.end());
  };
  const std::vector<Vec3> one = run(1), two = run(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].x(), two[i].x()) << i;
    EXPECT_EQ(one[i].y(), two[i].y()) << i;
    EXPECT_EQ(one[i].z(), two[i].z()) << i;
  }
}

// The settled sheet of two worlds, awake and still moving a little; one world's pins jump by
// `jump` (every pin the same), the other's stay. The twins solve tightly (the relative residual
// at 1e-3): their bits differ from the start (positions 10 m from the origin), and a loose solve
// lets such last-bit differences grow to the size of what it leaves unsolved, which is not what
// these tests measure. With the default velocity error at 1e-1 the carried and the staying sheet
// part by 1e-7–5e-7 m and 3e-6–2.5e-5 m/s over 1 s, against < 1e-9 m and 1e-7 m/s here.
ClothSettings tightlySolved(ClothSettings settings) {
  settings.solver.cgStopping = PcgStopping::RelativeResidual;
  settings.solver.cgTolerance = 1e-3;
  return settings;
}

struct TwinWorlds {
  World jumped, stayed;
  ClothId jumpedCloth, stayedCloth;
  explicit TwinWorlds(const ClothSettings& settings) {
    jumpedCloth = jumped.createCloth(sheet(), tightlySolved(settings)).value();
    stayedCloth = stayed.createCloth(sheet(), tightlySolved(settings)).value();
    for (int frame = 0; frame < 20; ++frame) {
      jumped.step(kFrameDt);
      stayed.step(kFrameDt);
    }
  }
};

// Jumps every pin of a hanging sheet 10 m at once and expects it to go on, carried, as its twin
// that stayed does.
void expectAllPinsJumpCarried(const ClothSettings& settings) {
  TwinWorlds twins(settings);
  const Vec3 jump(10.0, 2.0, -3.0);
  std::vector<Vec3> targets = twins.jumped.pinTargets(twins.jumpedCloth).value();
  for (Vec3& target : targets) target += jump;
  ASSERT_TRUE(twins.jumped.setPinTargets(twins.jumpedCloth, targets).ok());
  EXPECT_GT(twins.jumped.stats().kineticEnergy, 0.0);  // the sheet still moves when it jumps
  Real largestGap = 0, largestVelocityGap = 0;
  for (int frame = 0; frame < 60; ++frame) {
    const StepStatus status = twins.jumped.step(kFrameDt);
    twins.stayed.step(kFrameDt);
    EXPECT_EQ(status, StepStatus::Ok) << frame;
    EXPECT_EQ(twins.jumped.stats().teleportedCloths, frame == 0 ? 1u : 0u) << frame;
    EXPECT_EQ(twins.jumped.stats().substeps, 1) << frame;  // no pin moves relative to the cloth
    const auto x = twins.jumped.positions(twins.jumpedCloth).value();
    const auto v = twins.jumped.velocities(twins.jumpedCloth).value();
    const auto y = twins.stayed.positions(twins.stayedCloth).value();
    const auto w = twins.stayed.velocities(twins.stayedCloth).value();
    for (std::size_t i = 0; i < x.size(); ++i) {
      largestGap = std::max(largestGap, (x[i] - jump - y[i]).norm());
      largestVelocityGap = std::max(largestVelocityGap, (v[i] - w[i]).norm());
    }
    if (frame == 0) {
      // The jump's velocities are those of a sheet that did not jump, not 600 m/s.
      EXPECT_LT(twins.jumped.stats().maxSpeed, 1.0);
    }
  }
  std::printf("[pin teleport] carried sheet against the one that stayed over 1 s: %.3g m, %.3g m/s\n",
              largestGap, largestVelocityGap);
  // Only round-off apart (positions 10 m from the origin instead of 0.3 m).
  EXPECT_LT(largestGap, 1e-9);
  EXPECT_LT(largestVelocityGap, 1e-7);
  // Pins are at their targets bit for bit.
  const auto x = twins.jumped.positions(twins.jumpedCloth).value();
  const std::vector<Index>& pins = settings.pinnedVertices;
  for (std::size_t k = 0; k < pins.size(); ++k) EXPECT_EQ(x[pins[k]], targets[k]) << k;
}

TEST(PinTeleport, PinsThatAllJumpCarryTheClothWhichGoesOnAsIfNothingHappened) {
  ClothSettings settings = hangingCotton();
  settings.sleep.enabled = false;
  expectAllPinsJumpCarried(settings);
}

TEST(PinTeleport, ABdf2ClothCarriesItsHistoryWithItsPins) {
  // BDF2's step reads the previous step's positions: left behind, the 10 m jump would enter the
  // next step as a velocity.
  ClothSettings settings = hangingCotton();
  settings.sleep.enabled = false;
  settings.solver.integrator = IntegratorKind::Bdf2;
  expectAllPinsJumpCarried(settings);
}

// Cotton hanging from its top two rows: pins that are not collinear, so they determine a full
// rotation. (Pinned at its four corners instead, the sheet's own weight compresses the columns
// above the lower corners: it buckles out of its plane from round-off, and a turned copy, whose
// round-off differs, buckles its own way, 1 to 4 cm apart within 1 s.)
ClothSettings twoRowCotton() {
  ClothSettings settings;
  settings.material = cottonFabric();
  for (Index c = 0; c < 2 * kColumns; ++c) settings.pinnedVertices.push_back((kRows - 2) * kColumns + c);
  settings.sleep.enabled = false;
  return settings;
}

struct CarryGaps {
  Real position = 0, velocity = 0, speedAtJump = 0, stayedSpeedAtJump = 0;
  Index substepsOverOne = 0, teleportFrames = 0, notOk = 0;
};

// Twin worlds; the jumped one's pins move by x ↦ rotation · x + shift in one frame (its gravity
// turns with them when `turnGravity`, so the turned sheet feels what the other one feels), then
// both run 1 s. Gaps: the jumped sheet against the stayed one carried by the same motion.
CarryGaps jumpAndTurn(const ClothSettings& settings, const Mat3& rotation, const Vec3& shift,
                      bool turnGravity) {
  TwinWorlds twins(settings);
  std::vector<Vec3> targets = twins.jumped.pinTargets(twins.jumpedCloth).value();
  for (Vec3& target : targets) target = rotation * target + shift;
  EXPECT_TRUE(twins.jumped.setPinTargets(twins.jumpedCloth, targets).ok());
  if (turnGravity) {
    EXPECT_TRUE(twins.jumped.setGravity(rotation * Vec3(0, -9.81, 0)).ok());
  }
  EXPECT_GT(twins.jumped.stats().kineticEnergy, 0.0);  // the sheet still moves when it jumps
  CarryGaps gaps;
  for (int frame = 0; frame < 60; ++frame) {
    gaps.notOk += twins.jumped.step(kFrameDt) != StepStatus::Ok;
    twins.stayed.step(kFrameDt);
    gaps.teleportFrames += twins.jumped.stats().teleportedCloths;
    gaps.substepsOverOne += twins.jumped.stats().substeps != 1;
    if (frame == 0) {
      gaps.speedAtJump = twins.jumped.stats().maxSpeed;
      gaps.stayedSpeedAtJump = twins.stayed.stats().maxSpeed;
    }
    const auto x = twins.jumped.positions(twins.jumpedCloth).value();
    const auto v = twins.jumped.velocities(twins.jumpedCloth).value();
    const auto y = twins.stayed.positions(twins.stayedCloth).value();
    const auto w = twins.stayed.velocities(twins.stayedCloth).value();
    for (std::size_t i = 0; i < x.size(); ++i) {
      gaps.position = std::max(gaps.position, (x[i] - (rotation * y[i] + shift)).norm());
      gaps.velocity = std::max(gaps.velocity, (v[i] - rotation * w[i]).norm());
    }
  }
  return gaps;
}

void expectCarriedAsIfNothingHappened(const CarryGaps& gaps, const char* what) {
  std::printf("[pin teleport] %s: against the sheet that stayed over 1 s %.3g m, %.3g m/s\n",
              what, gaps.position, gaps.velocity);
  EXPECT_EQ(gaps.teleportFrames, 1) << what;
  EXPECT_EQ(gaps.notOk, 0) << what;
  EXPECT_EQ(gaps.substepsOverOne, 0) << what;  // no pin moves relative to the carried cloth
  // Not dragged through the turn: as fast as the sheet that stayed, not hundreds of m/s.
  EXPECT_LT(gaps.speedAtJump, gaps.stayedSpeedAtJump + 1e-6) << what;
  EXPECT_LT(gaps.position, 1e-9) << what;
  EXPECT_LT(gaps.velocity, 1e-7) << what;
}

Mat3 turn(Real angle, const Vec3& axis) {
  return Eigen::AngleAxis<Real>(angle, axis.normalized()).toRotationMatrix();
}

TEST(PinTeleport, PinsThatJumpAndTurnCarryTheClothTurned) {
  // A respawn facing the other way: 10 m and a half-turn about the vertical. Pins on the top two rows
  // (a full fit), gravity unchanged by the turn.
  const ClothSettings rows = twoRowCotton();
  expectCarriedAsIfNothingHappened(
      jumpAndTurn(rows, turn(std::numbers::pi, Vec3::UnitY()), Vec3(10.0, 0.0, -4.0), false),
      "top two rows, 10 m and a half-turn about the vertical");
  // An arbitrary axis and angle: gravity turns with the pins, so both sheets feel the same.
  expectCarriedAsIfNothingHappened(
      jumpAndTurn(rows, turn(2.1, Vec3(0.3, -0.5, 0.8)), Vec3(-3.0, 7.0, 5.0), true),
      "top two rows, 2.1 rad about (0.3, -0.5, 0.8)");
}

TEST(PinTeleport, CollinearPinsCarryTheTurnTheyDetermine) {
  // A strip hanging from its top row (collinear pins; the turn about their line is undetermined).
  ClothSettings strip = hangingCotton();
  strip.sleep.enabled = false;
  // A cape on a character respawned facing the other way: the line turns end for end, where the
  // smallest rotation has no axis; gravity's axis decides, so the sheet still hangs.
  expectCarriedAsIfNothingHappened(
      jumpAndTurn(strip, turn(std::numbers::pi, Vec3::UnitY()), Vec3(10.0, 0.0, 0.0), false),
      "top row, 10 m and a half-turn about the vertical");
  expectCarriedAsIfNothingHappened(
      jumpAndTurn(strip, turn(std::numbers::pi / 2, Vec3::UnitY()), Vec3(0.0, 0.0, 10.0), false),
      "top row, 10 m and a quarter-turn about the vertical");
  // Turned about a horizontal axis across the line, gravity turning with it.
  expectCarriedAsIfNothingHappened(
      jumpAndTurn(strip, turn(std::numbers::pi / 3, Vec3::UnitZ()), Vec3(5.0, -8.0, 2.0), true),
      "top row, 10 m and 60 degrees about an axis across it");
}

TEST(PinTeleport, OnePinCarriesItsJumpOnly) {
  // One pin determines no rotation: carried by its jump, the sheet goes on as the one that stayed.
  ClothSettings corner;
  corner.material = cottonFabric();
  corner.pinnedVertices = {kRows * kColumns - 1};
  corner.sleep.enabled = false;
  expectCarriedAsIfNothingHappened(jumpAndTurn(corner, Mat3::Identity(), Vec3(10.0, 2.0, -3.0), false),
                                   "one pin, 10 m");
}

// The rigid motion x ↦ R (x − centre) + centre as jumpAndTurn's rotation and shift.
Vec3 shiftTurningAbout(const Mat3& rotation, const Vec3& centre) { return centre - rotation * centre; }

TEST(PinTeleport, PinsTurnedInPlaceBeyondTheAngleCarryTheCloth) {
  // The pins of the top row turned end for end about the vertical through their middle: the
  // middle pin stays, so the distance rule cannot see it; the angle rule carries the sheet.
  ClothSettings strip = hangingCotton();
  strip.sleep.enabled = false;
  const Vec3 middle = sheet()->restPositions()[(kRows - 1) * kColumns + kColumns / 2];
  const Mat3 halfTurn = turn(std::numbers::pi, Vec3::UnitY());
  expectCarriedAsIfNothingHappened(jumpAndTurn(strip, halfTurn, shiftTurningAbout(halfTurn, middle), false),
                                   "top row, a half-turn about its middle");
  // Two rows (a full fit) turned 2 rad about a tilted axis through a point off the sheet, gravity
  // turning with them.
  const Mat3 tilted = turn(2.0, Vec3(0.2, 1.0, 0.4));
  expectCarriedAsIfNothingHappened(
      jumpAndTurn(twoRowCotton(), tilted, shiftTurningAbout(tilted, Vec3(0.1, 1.2, -0.2)), true),
      "top two rows, 2 rad about a tilted axis near the sheet");
}

TEST(PinTeleport, PinsTurnedLessThanTheAngleOrNotRigidlyAreDragged) {
  const auto model = sheet();
  const Vec3 middle = model->restPositions()[(kRows - 1) * kColumns + kColumns / 2];
  struct Case {
    const char* what;
    Real angle;           // rad, about the vertical through the top row's middle
    bool secondRowStays;  // the second row of pins stays: the pins deform the cloth
    Real teleportAngle;   // SolverSettings::pinTeleportAngle
  };
  const Case cases[] = {
      {"top row turned 89 degrees", 89 * std::numbers::pi / 180, false, std::numbers::pi / 2},
      {"top row turned a half-turn, second row staying", std::numbers::pi, true, std::numbers::pi / 2},
      {"top row turned a half-turn, the angle rule off", std::numbers::pi, false, 0},
  };
  for (const Case& c : cases) {
    World world;
    ClothSettings settings = c.secondRowStays ? twoRowCotton() : hangingCotton();
    settings.solver.pinTeleportAngle = c.teleportAngle;
    const ClothId cloth = world.createCloth(model, settings).value();
    std::vector<Vec3> targets = world.pinTargets(cloth).value();
    const Mat3 rotation = turn(c.angle, Vec3::UnitY());
    const std::vector<Index>& pins = settings.pinnedVertices;
    for (std::size_t k = 0; k < pins.size(); ++k) {
      if (pins[k] >= (kRows - 1) * kColumns) targets[k] = rotation * (targets[k] - middle) + middle;
    }
    ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
    const StepStatus status = world.step(kFrameDt);
    EXPECT_EQ(world.stats().teleportedCloths, 0u) << c.what;
    EXPECT_GT(world.stats().substeps, 1) << c.what;  // the substep rule follows the far pins
    const Real dragStrain = world.stats().maxStrain;
    Real settledStrain = 0;
    for (int frame = 0; frame < 120; ++frame) {
      world.step(kFrameDt);
      settledStrain = world.stats().maxStrain;
    }
    std::printf("[pin teleport] %s, dragged: max strain %.4f at the frame's end (%s), %.4f 2 s later\n",
                c.what, dragStrain, describe(status).c_str(), settledStrain);
    if (c.angle < std::numbers::pi / 2) {
      // A turn the default leaves to the simulation: the cloth buckles through it and stays
      // within its strain limit (0.10, + 1 %).
      EXPECT_LE(dragStrain, 0.101) << c.what;
      EXPECT_LE(settledStrain, 0.101) << c.what;
    }
  }
}

TEST(PinTeleport, ANegativeOrNonFiniteTeleportAngleIsRefusedByName) {
  World world;
  for (Real bad : {Real(-0.1), std::nan(""), std::numeric_limits<Real>::infinity()}) {
    ClothSettings settings = hangingCotton();
    settings.solver.pinTeleportAngle = bad;
    const Result<ClothId> cloth = world.createCloth(sheet(), settings);
    ASSERT_FALSE(cloth.ok());
    EXPECT_NE(cloth.error().message.find("pinTeleportAngle"), std::string::npos)
        << cloth.error().message;
  }
  EXPECT_EQ(world.clothCount(), 0u);
}

TEST(PinTeleport, OnePinYankedAloneOrAShortJumpIsDraggedNotCarried) {
  // Each in a world of its own: the three cloths would lie on one another.
  const auto model = sheet();
  ClothSettings settings = hangingCotton();
  settings.selfCollision = false;
  const Real size = model->characteristicLength();
  // One corner pin yanked 2 m (40 times the edge to its neighbour pin): the substep rule follows
  // it, and the frame ends with the cloth torn between the pins as far as they demand, flagged.
  World yankedWorld;
  const ClothId yanked = yankedWorld.createCloth(model, settings).value();
  std::vector<Vec3> targets = yankedWorld.pinTargets(yanked).value();
  targets[0].x() += 2.0;
  ASSERT_TRUE(yankedWorld.setPinTargets(yanked, targets).ok());
  EXPECT_EQ(yankedWorld.plannedSubsteps(yanked, kFrameDt).value(),
            Index(std::ceil(2.0 / meanEdgeLength(*model) * (1 - 1e-9))));
  const StepStatus yankedStatus = yankedWorld.step(kFrameDt);
  EXPECT_EQ(yankedWorld.stats().teleportedCloths, 0u);
  EXPECT_TRUE(hasFlag(yankedStatus, StepStatus::StrainLimitExceeded)) << describe(yankedStatus);
  EXPECT_FALSE(hasFlag(yankedStatus, StepStatus::RolledBack)) << describe(yankedStatus);
  EXPECT_EQ(yankedWorld.positions(yanked).value()[settings.pinnedVertices[0]], targets[0]);
  // Every pin moving 0.9 of the cloth's size: dragged (more than one edge, so more substeps).
  World shortWorld;
  const ClothId shortJump = shortWorld.createCloth(model, settings).value();
  targets = shortWorld.pinTargets(shortJump).value();
  for (Vec3& target : targets) target.z() += 0.9 * size;
  ASSERT_TRUE(shortWorld.setPinTargets(shortJump, targets).ok());
  EXPECT_EQ(shortWorld.plannedSubsteps(shortJump, kFrameDt).value(),
            Index(std::ceil(0.9 * size / meanEdgeLength(*model) * (1 - 1e-9))));
  shortWorld.step(kFrameDt);
  EXPECT_EQ(shortWorld.stats().teleportedCloths, 0u);
  // Its far edge lags behind its pins.
  EXPECT_LT(shortWorld.positions(shortJump).value()[0].z(), 0.9 * size - 1e-3);
  // 1.1 of its size: carried, one substep.
  World longWorld;
  const ClothId longJump = longWorld.createCloth(model, settings).value();
  targets = longWorld.pinTargets(longJump).value();
  for (Vec3& target : targets) target.z() += 1.1 * size;
  ASSERT_TRUE(longWorld.setPinTargets(longJump, targets).ok());
  EXPECT_EQ(longWorld.plannedSubsteps(longJump, kFrameDt).value(), 1);
  longWorld.step(kFrameDt);
  EXPECT_EQ(longWorld.stats().teleportedCloths, 1u);
  EXPECT_NEAR(longWorld.positions(longJump).value()[0].z(), 1.1 * size, 1e-3);
}

TEST(PinTeleport, PinTargetsThatTearAnEdgeBetweenPinsAreRefusedByName) {
  // One corner of the pinned top row yanked 10 m: the edge to its neighbour pin would be 200
  // times its rest length, which the health check rolls back however many substeps are taken.
  World world;
  ClothSettings settings = hangingCotton();
  const ClothId cloth = world.createCloth(sheet(), settings).value();
  world.step(kFrameDt);
  const std::vector<Vec3> before = world.pinTargets(cloth).value();
  const std::vector<Vec3> positions(world.positions(cloth).value().begin(),
                                    world.positions(cloth).value().end());
  std::vector<Vec3> targets = before;
  targets[0].x() += 10.0;
  const Status torn = world.setPinTargets(cloth, targets);
  ASSERT_FALSE(torn.ok());
  const std::string& message = torn.error().message;
  for (const std::string& named :
       {std::to_string(settings.pinnedVertices[0]), std::to_string(settings.pinnedVertices[1]),
        std::string("unpin")}) {
    EXPECT_NE(message.find(named), std::string::npos) << message;
  }
  // Nothing changed: the targets are the old ones and the cloth steps on as it hung.
  EXPECT_EQ(world.pinTargets(cloth).value(), before);
  const StepStatus status = world.step(kFrameDt);
  EXPECT_FALSE(hasFlag(status, StepStatus::RolledBack)) << describe(status);
  EXPECT_LT((world.positions(cloth).value()[0] - positions[0]).norm(), 0.01);
  // Pins one edge apart may be moved as far as the check allows (99 times the edge's stretch).
  targets = before;
  targets[0].x() -= 50 * (before[1] - before[0]).norm();
  EXPECT_TRUE(world.setPinTargets(cloth, targets).ok());
}

TEST(PinTeleport, ANegativeOrNonFiniteTeleportDistanceIsRefusedByName) {
  World world;
  for (Real bad : {Real(-0.5), std::nan(""), std::numeric_limits<Real>::infinity()}) {
    ClothSettings settings = hangingCotton();
    settings.solver.pinTeleportDistance = bad;
    const Result<ClothId> cloth = world.createCloth(sheet(), settings);
    ASSERT_FALSE(cloth.ok());
    EXPECT_NE(cloth.error().message.find("pinTeleportDistance"), std::string::npos)
        << cloth.error().message;
  }
  EXPECT_EQ(world.clothCount(), 0u);
}

TEST(PinTeleport, ASleepingClothReportsThePotentialEnergyItSettledWith) {
  World world;
  const ClothId cloth = world.createCloth(sheet(), hangingCotton()).value();
  Real lastAwakePotential = 0;
  int frame = 0;
  for (; frame < 900 && !world.isSleeping(cloth).value(); ++frame) {
    world.step(kFrameDt);  // stepped (it falls asleep at the end of a stepped frame)
    lastAwakePotential = world.stats().potentialEnergy;
  }
  ASSERT_TRUE(world.isSleeping(cloth).value()) << "the hanging sheet never fell asleep";
  // Gravity's part alone, −Σ m g·x with the sheet around y = 0.85 m, is far from 0.
  EXPECT_GT(lastAwakePotential, 0.1);
  const StepStatus status = world.step(kFrameDt);
  ASSERT_EQ(world.stats().sleepingCloths, 1u) << describe(status);
  // The frame in which it fell asleep ended with the velocities zeroed; the potential reported
  // is that frame's, bit for bit.
  EXPECT_EQ(world.stats().potentialEnergy, lastAwakePotential);
  EXPECT_EQ(world.stats().kineticEnergy, 0.0);
}

}  // namespace
}  // namespace weft
