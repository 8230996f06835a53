// Attachments of pinned vertices to moving colliders, per-vertex external forces and runtime
// wind: the parts of the World API a game uses to drive cloth from its own objects.
#include <weft/collision/Sphere.h>
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace weft {
namespace {

using ::testing::HasSubstr;

constexpr Index kColumns = 9, kRows = 7;

std::shared_ptr<const ClothModel> strip() {
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 0.4;
  grid.height = 0.3;
  grid.origin = {-0.2, 0.7, 0.0};
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

std::vector<Index> topRow() {
  std::vector<Index> row;
  for (Index c = 0; c < kColumns; ++c) row.push_back((kRows - 1) * kColumns + c);
  return row;
}

// A small sphere well above the cloth: it carries the attachments without touching the cloth.
ColliderId addCarrier(World& world, const RigidMotion& motion) {
  return world.addCollider(Sphere::create(0.02, motion).value()).value();
}

TEST(Attachment, PinnedVerticesFollowATranslatingCollider) {
  World world(WorldSettings{.threadCount = 1});
  ClothSettings settings;
  settings.pinnedVertices = topRow();
  const ClothId cloth = world.createCloth(strip(), settings).value();
  RigidMotion carrier;
  carrier.pose.position = {0.0, 1.5, 0.0};
  carrier.linearVelocity = {0.6, 0.0, 0.3};
  const ColliderId hand = addCarrier(world, carrier);
  const std::vector<Index> row = topRow();
  ASSERT_TRUE(world.attachToCollider(cloth, row, hand).ok());
  EXPECT_EQ(world.attachedVertexCount(cloth).value(), kColumns);
  const std::vector<Vec3> start(world.positions(cloth).value().begin(),
                                world.positions(cloth).value().end());
  const int frames = 30;
  for (int frame = 0; frame < frames; ++frame) world.step(1.0 / 60.0);
  const Vec3 moved = carrier.linearVelocity * (frames / 60.0);
  const std::span<const Vec3> x = world.positions(cloth).value();
  for (Index vertex : row) {
    EXPECT_LT((x[vertex] - (start[vertex] + moved)).norm(), 1e-12) << "vertex " << vertex;
  }
  // The free part was dragged along, not left behind.
  EXPECT_GT(x[0].x() - start[0].x(), 0.5 * moved.x());
}

TEST(Attachment, PinnedVerticesTurnWithARotatingCollider) {
  World world(WorldSettings{.threadCount = 1});
  ClothSettings settings;
  settings.pinnedVertices = topRow();
  const ClothId cloth = world.createCloth(strip(), settings).value();
  RigidMotion pole;  // a vertical pole through x = 0 turning half a turn per second
  pole.pose.position = {0.0, 1.5, 0.0};
  pole.angularVelocity = {0.0, std::numbers::pi, 0.0};
  const ColliderId hand = addCarrier(world, pole);
  const std::vector<Index> row = topRow();
  ASSERT_TRUE(world.attachToCollider(cloth, row, hand).ok());
  const std::vector<Vec3> start(world.positions(cloth).value().begin(),
                                world.positions(cloth).value().end());
  for (int frame = 0; frame < 30; ++frame) world.step(1.0 / 60.0);  // half a second: 90°
  const std::span<const Vec3> x = world.positions(cloth).value();
  for (Index vertex : row) {
    // A quarter turn about +y takes (x, y, z) to (z, y, −x).
    const Vec3 expected{start[vertex].z(), start[vertex].y(), -start[vertex].x()};
    EXPECT_LT((x[vertex] - expected).norm(), 1e-9) << "vertex " << vertex;
  }
}

TEST(Attachment, RefusesVerticesThatAreNotPinnedAndChangesNothing) {
  World world;
  ClothSettings settings;
  settings.pinnedVertices = topRow();
  const ClothId cloth = world.createCloth(strip(), settings).value();
  const ColliderId hand = addCarrier(world, RigidMotion{});
  const Index free[] = {topRow()[0], 3};
  Status status = world.attachToCollider(cloth, free, hand);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.error().message, HasSubstr("vertex 3 is not pinned"));
  EXPECT_EQ(world.attachedVertexCount(cloth).value(), 0u);
  const Index outOfRange[] = {kColumns * kRows};
  status = world.attachToCollider(cloth, outOfRange, hand);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.error().message, HasSubstr("out of range"));
  const Index one[] = {topRow()[0]};
  EXPECT_THAT(world.attachToCollider(cloth, one, ColliderId{}).error().message,
              HasSubstr("is null"));
  EXPECT_THAT(world.attachToCollider(ClothId{}, one, hand).error().message, HasSubstr("is null"));
  EXPECT_EQ(world.attachedVertexCount(cloth).value(), 0u);
}

TEST(Attachment, DestroyingTheColliderLeavesThePinsWhereTheyAre) {
  World world(WorldSettings{.threadCount = 1});
  ClothSettings settings;
  settings.pinnedVertices = topRow();
  const ClothId cloth = world.createCloth(strip(), settings).value();
  RigidMotion carrier;
  carrier.pose.position = {0.0, 1.5, 0.0};
  carrier.linearVelocity = {0.0, 0.0, 1.0};
  const ColliderId hand = addCarrier(world, carrier);
  const std::vector<Index> row = topRow();
  ASSERT_TRUE(world.attachToCollider(cloth, row, hand).ok());
  for (int frame = 0; frame < 10; ++frame) world.step(1.0 / 60.0);
  ASSERT_TRUE(world.destroyCollider(hand).ok());
  EXPECT_EQ(world.attachedVertexCount(cloth).value(), 0u);
  const Vec3 held = world.positions(cloth).value()[row[0]];
  for (int frame = 0; frame < 10; ++frame) world.step(1.0 / 60.0);
  EXPECT_LT((world.positions(cloth).value()[row[0]] - held).norm(), 1e-12);
}

TEST(Attachment, DetachedVerticesStopFollowing) {
  World world(WorldSettings{.threadCount = 1});
  ClothSettings settings;
  settings.pinnedVertices = topRow();
  const ClothId cloth = world.createCloth(strip(), settings).value();
  RigidMotion carrier;
  carrier.pose.position = {0.0, 1.5, 0.0};
  carrier.linearVelocity = {0.0, 0.0, 1.0};
  const ColliderId hand = addCarrier(world, carrier);
  const std::vector<Index> row = topRow();
  ASSERT_TRUE(world.attachToCollider(cloth, row, hand).ok());
  const Index left[] = {row[0]};
  ASSERT_TRUE(world.detachFromCollider(cloth, left).ok());
  EXPECT_EQ(world.attachedVertexCount(cloth).value(), kColumns - 1);
  const Vec3 before = world.positions(cloth).value()[row[0]];
  for (int frame = 0; frame < 6; ++frame) world.step(1.0 / 60.0);
  EXPECT_LT((world.positions(cloth).value()[row[0]] - before).norm(), 1e-12);
  EXPECT_NEAR(world.positions(cloth).value()[row.back()].z(), 0.1, 1e-12);
}

// With no gravity, no drag and no pins, internal forces cancel: the momentum grows by exactly
// the applied impulse, Σ f·t, whatever the integrator does with the internal forces.
TEST(ExternalForces, ChangeMomentumByTheAppliedImpulse) {
  World world(WorldSettings{.gravity = {0, 0, 0}, .threadCount = 1});
  ClothSettings settings;
  settings.material.airDrag = 0;
  settings.selfCollision = false;
  // Implicit Euler conserves momentum only as well as its linear systems are solved.
  settings.solver.cgTolerance = 1e-12;
  settings.solver.cgMaxIterations = 2000;
  const std::shared_ptr<const ClothModel> shared = strip();
  const ClothId cloth = world.createCloth(shared, settings).value();
  const Index n = kColumns * kRows;
  std::vector<Vec3> forces(n, Vec3::Zero());
  forces[0] = {0.0, 0.0, 0.02};  // a corner pulled out of plane and one pushed sideways
  forces[n - 1] = {0.01, 0.0, 0.0};
  ASSERT_TRUE(world.setExternalForces(cloth, forces).ok());
  const int frames = 20;
  for (int frame = 0; frame < frames; ++frame) world.step(1.0 / 60.0);
  const std::span<const Vec3> v = world.velocities(cloth).value();
  const ClothModel& model = *shared;
  Vec3 momentum = Vec3::Zero();
  for (Index i = 0; i < n; ++i) momentum += settings.material.arealDensity * model.vertexAreas()[i] * v[i];
  const Vec3 impulse = (forces[0] + forces[n - 1]) * (frames / 60.0);
  EXPECT_LT((momentum - impulse).norm(), 1e-6 * impulse.norm());
  // Removing them stops the acceleration: momentum is conserved from then on.
  ASSERT_TRUE(world.setExternalForces(cloth, {}).ok());
  for (int frame = 0; frame < 10; ++frame) world.step(1.0 / 60.0);
  Vec3 after = Vec3::Zero();
  const std::span<const Vec3> v2 = world.velocities(cloth).value();
  for (Index i = 0; i < n; ++i) after += settings.material.arealDensity * model.vertexAreas()[i] * v2[i];
  EXPECT_LT((after - momentum).norm(), 1e-6 * impulse.norm());
}

TEST(ExternalForces, BadForcesAreRefusedAndChangeNothing) {
  World world;
  const ClothId cloth = world.createCloth(strip(), ClothSettings{}).value();
  std::vector<Vec3> tooFew(3, Vec3::Zero());
  EXPECT_THAT(world.setExternalForces(cloth, tooFew).error().message,
              HasSubstr("got 3 forces for a cloth of 63 vertices"));
  std::vector<Vec3> bad(kColumns * kRows, Vec3::Zero());
  bad[5].y() = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THAT(world.setExternalForces(cloth, bad).error().message, HasSubstr("vertex 5"));
  EXPECT_THAT(world.setExternalForces(ClothId{}, {}).error().message, HasSubstr("is null"));
  // Nothing was stored: the cloth falls exactly like an untouched twin.
  World twin;
  const ClothId other = twin.createCloth(strip(), ClothSettings{}).value();
  world.step(1.0 / 60.0);
  twin.step(1.0 / 60.0);
  EXPECT_EQ(world.positions(cloth).value()[0], twin.positions(other).value()[0]);
}

TEST(Wind, ChangesAtRunTimeAndPushesTheCloth) {
  World world(WorldSettings{.gravity = {0, 0, 0}, .threadCount = 1});
  ClothSettings settings;
  settings.material.airDrag = 1.0;
  const ClothId cloth = world.createCloth(strip(), settings).value();
  world.step(1.0 / 60.0);
  EXPECT_EQ(world.velocities(cloth).value()[10].norm(), 0.0);  // still air
  ASSERT_TRUE(world.setWind({0.0, 0.0, 2.0}).ok());
  EXPECT_EQ(world.wind().z(), 2.0);
  for (int frame = 0; frame < 10; ++frame) world.step(1.0 / 60.0);
  EXPECT_GT(world.velocities(cloth).value()[10].z(), 0.0);
  EXPECT_THAT(world.setWind({std::numeric_limits<Real>::infinity(), 0, 0}).error().message,
              HasSubstr("NaN or infinite"));
  EXPECT_EQ(world.wind().z(), 2.0);
}

}  // namespace
}  // namespace weft
