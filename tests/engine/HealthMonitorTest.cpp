// The health monitor names why a frame failed (StepStats::healthFailure), never lets a NaN out,
// and reports nothing on healthy frames.
#include <weft/collision/Sphere.h>
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace weft {
namespace {

std::shared_ptr<const ClothModel> smallGrid() {
  GridSettings grid;
  grid.columns = 11;
  grid.rows = 9;
  grid.width = 0.5;
  grid.height = 0.4;
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

ClothSettings pinnedTopRow() {
  ClothSettings settings;
  for (Index c = 0; c < 11; ++c) settings.pinnedVertices.push_back(8 * 11 + c);
  return settings;
}

TEST(HealthMonitor, NamesEveryCause) {
  EXPECT_STREQ(describe(HealthFailure::None), "none");
  EXPECT_STREQ(describe(HealthFailure::NonFinite), "non-finite");
  EXPECT_STREQ(describe(HealthFailure::Speed), "speed");
  EXPECT_STREQ(describe(HealthFailure::Strain), "strain");
  EXPECT_STREQ(describe(HealthFailure::EnergyJump), "energy-jump");
  EXPECT_STREQ(describe(HealthFailure::OutOfRange), "out-of-range");
}

TEST(HealthMonitor, ADivergingFrameIsRolledBackWithItsCause) {
  World world;
  ClothSettings settings = pinnedTopRow();
  settings.solver.integrator = IntegratorKind::ExplicitEuler;
  settings.solver.substeps = 1;  // far beyond the stable step
  settings.material.stretchDamping = 0;
  settings.material.shearDamping = 0;
  const ClothId cloth = world.createCloth(smallGrid(), settings).value();
  bool sawFailure = false;
  for (int frame = 0; frame < 100 && !sawFailure; ++frame) {
    const std::uint64_t before = world.stateHash();
    const StepStatus status = world.step(1.0 / 60.0);
    if (!hasFlag(status, StepStatus::RolledBack)) continue;
    sawFailure = true;
    // Rolled back: the cloth is where the frame started, and the cause is named.
    EXPECT_EQ(world.stateHash(), before);
    EXPECT_NE(world.stats().healthFailure, HealthFailure::None);
    EXPECT_THAT(std::string(describe(world.stats().healthFailure)),
                ::testing::AnyOf("non-finite", "speed", "strain", "energy-jump"));
    std::printf("rolled back at frame %d: %s, cause %s\n", frame, describe(status).c_str(),
                describe(world.stats().healthFailure));
  }
  EXPECT_TRUE(sawFailure);
  for (const Vec3& x : world.positions(cloth).value()) ASSERT_TRUE(x.allFinite());
}

TEST(HealthMonitor, HealthyFramesReportNoCause) {
  World world;
  (void)world.createCloth(smallGrid(), pinnedTopRow()).value();
  for (int frame = 0; frame < 30; ++frame) {
    ASSERT_EQ(world.step(1.0 / 60.0), StepStatus::Ok);
    ASSERT_EQ(world.stats().healthFailure, HealthFailure::None);
  }
}

TEST(HealthMonitor, AFastButPhysicalThrowIsNotAFailure) {
  // A cloth thrown at 200 m/s stays well inside every threshold: the monitor is an alarm for
  // divergence, not a speed limit.
  World world;
  const ClothId cloth = world.createCloth(smallGrid(), ClothSettings{}).value();
  const std::span<const Vec3> x = world.positions(cloth).value();
  const Vec3Array positions(x.begin(), x.end());
  ASSERT_TRUE(world.setState(cloth, positions, Vec3Array(positions.size(), Vec3(200, 0, 0))).ok());
  for (int frame = 0; frame < 10; ++frame) {
    ASSERT_EQ(world.step(1.0 / 60.0), StepStatus::Ok) << describe(world.stats().healthFailure);
  }
}

TEST(HealthMonitor, AClothCarriedBeyondTheSimulatedRangeIsRolledBack) {
  // One frame of 1e308 s (BadInput's clock test) carries a pinned sheet far beyond 1e9 m
  // (kMaxSimulatedCoordinate), where doubles cannot resolve its thickness: the attempt fails at
  // its first substep, instead of testing every pair of triangles in thousands of substeps, and
  // the frame is rolled back with its cause; the cloth is where it was.
  World world;
  const ClothId cloth = world.createCloth(smallGrid(), pinnedTopRow()).value();
  (void)world.addCollider(Sphere::create(0.1, RigidMotion{{Vec3(0, 0, -1)}}).value()).value();
  for (int frame = 0; frame < 3; ++frame) ASSERT_EQ(world.step(1.0 / 60.0), StepStatus::Ok);
  const std::uint64_t before = world.stateHash();
  const StepStatus status = world.step(1e308);
  EXPECT_TRUE(hasFlag(status, StepStatus::RolledBack)) << describe(status);
  EXPECT_EQ(world.stats().healthFailure, HealthFailure::OutOfRange)
      << describe(world.stats().healthFailure);
  EXPECT_EQ(world.stateHash(), before);
  for (const Vec3& x : world.positions(cloth).value()) ASSERT_TRUE(x.allFinite());
}

}  // namespace
}  // namespace weft
