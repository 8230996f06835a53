// Sleeping (ClothSettings::sleep): a cloth at rest stops being simulated, stays where it settled
// (near equilibrium, not frozen away from it), and wakes on a pin move, on a collider coming near
// and on a force change.
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <cmath>

namespace weft {
namespace {

constexpr Real kFrameDt = 1.0 / 60;
constexpr Index kColumns = 9, kRows = 7;

std::shared_ptr<const ClothModel> sheet() {
  GridSettings settings;
  settings.columns = kColumns;
  settings.rows = kRows;
  settings.width = 0.4;
  settings.height = 0.3;
  settings.origin = Vec3(-0.2, 1.0, 0.0);
  return std::make_shared<const ClothModel>(ClothModel::grid(settings).value());
}

ClothSettings hanging(bool sleep) {
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  settings.sleep.enabled = sleep;
  return settings;
}

// Steps until the cloth sleeps; returns the frames it took (or `limit` + 1).
int stepUntilAsleep(World& world, ClothId cloth, int limit) {
  for (int frame = 1; frame <= limit; ++frame) {
    world.step(kFrameDt);
    if (world.isSleeping(cloth).value()) return frame;
  }
  return limit + 1;
}

Real maxDistance(std::span<const Vec3> a, std::span<const Vec3> b) {
  Real distance = 0;
  for (std::size_t i = 0; i < a.size(); ++i) distance = std::max(distance, (a[i] - b[i]).norm());
  return distance;
}

TEST(Sleep, AHangingClothSleepsNearItsEquilibriumAndCostsNothing) {
  World sleeping, awake;
  const ClothId a = sleeping.createCloth(sheet(), hanging(true)).value();
  const ClothId b = awake.createCloth(sheet(), hanging(false)).value();
  const int frames = stepUntilAsleep(sleeping, a, 900);
  ASSERT_LE(frames, 900) << "the hanging sheet never fell asleep";
  for (int k = 0; k < frames; ++k) awake.step(kFrameDt);
  const std::vector<Vec3> asleepAt(sleeping.positions(a).value().begin(), sleeping.positions(a).value().end());
  // Asleep: nothing moves, no stage runs, and the kinetic energy is zero.
  for (int k = 0; k < 60; ++k) {
    sleeping.step(kFrameDt);
    awake.step(kFrameDt);
    EXPECT_EQ(sleeping.stats().sleepingCloths, 1u);
    EXPECT_EQ(sleeping.stats().substeps, 0u);
    EXPECT_EQ(sleeping.stats().linearSolves, 0);
    EXPECT_EQ(sleeping.stats().kineticEnergy, 0.0);
  }
  EXPECT_EQ(maxDistance(sleeping.positions(a).value(), asleepAt), 0.0);
  // Approximate, and by how much: within a millimetre of the cloth that kept simulating.
  EXPECT_LT(maxDistance(sleeping.positions(a).value(), awake.positions(b).value()), 1e-3);
}

TEST(Sleep, AClothStillButPulledByForcesDoesNotSleep) {
  // Held out level and released from rest: zero speed at the start, but gravity pulls. Even with
  // a speed threshold that everything passes and a single quiet frame required, the acceleration
  // test keeps it awake.
  World world;
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 0.4;
  grid.height = 0.3;
  grid.heightAxis = Vec3(0, 0, 1);  // level
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back(c);
  settings.sleep.speed = 1e3;
  settings.sleep.frames = 1;
  const ClothId cloth = world.createCloth(model, settings).value();
  const Real startY = world.positions(cloth).value()[(kRows - 1) * kColumns].y();
  for (int k = 0; k < 30; ++k) {
    world.step(kFrameDt);
    ASSERT_FALSE(world.isSleeping(cloth).value()) << "frame " << k + 1;
  }
  EXPECT_LT(world.positions(cloth).value()[(kRows - 1) * kColumns].y(), startY - 0.05);
}

TEST(Sleep, WakesWhenAPinMoves) {
  World world;
  const ClothId cloth = world.createCloth(sheet(), hanging(true)).value();
  ASSERT_LE(stepUntilAsleep(world, cloth, 900), 900);
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  world.step(kFrameDt);
  ASSERT_TRUE(world.isSleeping(cloth).value());
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());  // the same targets: no reason to wake
  world.step(kFrameDt);
  EXPECT_TRUE(world.isSleeping(cloth).value());
  for (Vec3& target : targets) target.x() += 0.01;
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
  world.step(kFrameDt);
  EXPECT_FALSE(world.isSleeping(cloth).value());
  EXPECT_EQ(world.stats().wokenCloths, 1u);
  EXPECT_GT(world.stats().kineticEnergy, 0.0);
}

TEST(Sleep, WakesWhenAColliderComesNearButNotForOneFarAway) {
  World world;
  const ClothId cloth = world.createCloth(sheet(), hanging(true)).value();
  ASSERT_LE(stepUntilAsleep(world, cloth, 900), 900);
  // A ball moving 3 m away does not wake it.
  RigidMotion far;
  far.pose.position = Vec3(0, 1, 3);
  far.linearVelocity = Vec3(0, 0, 0.5);
  const ColliderId ball = world.addCollider(Sphere::create(0.1, far).value()).value();
  world.step(kFrameDt);
  EXPECT_TRUE(world.isSleeping(cloth).value());
  // Brought next to the cloth and moving into it: the cloth wakes and is pushed.
  RigidMotion near;
  near.pose.position = Vec3(0, 1.1, -0.12);
  near.linearVelocity = Vec3(0, 0, 0.5);
  ASSERT_TRUE(world.setColliderMotion(ball, near).ok());
  world.step(kFrameDt);
  EXPECT_FALSE(world.isSleeping(cloth).value());
  EXPECT_EQ(world.stats().wokenCloths, 1u);
  for (int k = 0; k < 20; ++k) world.step(kFrameDt);
  EXPECT_GT(world.stats().contacts + world.stats().colliderNarrowPhases, 0u);
}

TEST(Sleep, WakesWhenTheWindChangesAndOnRequest) {
  World world;
  ClothSettings settings = hanging(true);
  settings.material.airDrag = 0.5;
  const ClothId cloth = world.createCloth(sheet(), settings).value();
  ASSERT_LE(stepUntilAsleep(world, cloth, 900), 900);
  ASSERT_TRUE(world.setWind(Vec3(0, 0, 2)).ok());
  world.step(kFrameDt);
  EXPECT_FALSE(world.isSleeping(cloth).value());
  EXPECT_GT(world.stats().kineticEnergy, 0.0);
  EXPECT_FALSE(world.setWind(Vec3(0, std::nan(""), 0)).ok());
  EXPECT_FALSE(world.setGravity(Vec3(0, 0, INFINITY)).ok());
  // wake() on an awake cloth is harmless; on a stale handle it is an error.
  EXPECT_TRUE(world.wake(cloth).ok());
  EXPECT_FALSE(world.wake(ClothId{}).ok());
}

TEST(Sleep, SaveAndRestoreKeepTheSleepState) {
  World world;
  const ClothId cloth = world.createCloth(sheet(), hanging(true)).value();
  ASSERT_LE(stepUntilAsleep(world, cloth, 900), 900);
  const WorldState saved = world.saveState();
  ASSERT_TRUE(world.wake(cloth).ok());
  world.step(kFrameDt);
  ASSERT_TRUE(world.restoreState(saved).ok());
  EXPECT_TRUE(world.isSleeping(cloth).value());
}

}  // namespace
}  // namespace weft
