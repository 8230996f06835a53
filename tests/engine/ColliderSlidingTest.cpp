// A collider contact may only push: a sphere that pushes into a hanging sheet and then
// withdraws faster than the sheet falls back must leave it behind, not drag it along, and a
// floor must let go of cloth pulled up off it.
#include "ContactTestSupport.h"

#include <weft/collision/Plane.h>
#include <weft/collision/Sphere.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

namespace weft {
namespace {

struct SheetAndSphere {
  std::unique_ptr<World> world;
  ClothId cloth;
  ColliderId sphere;
};

// A 1 m × 0.75 m sheet pinned along its top, and a sphere that comes from behind (−z) and has
// pushed the sheet 0.2 m forward after 45 frames.
SheetAndSphere pushedSheet() {
  constexpr Index kColumns = 21, kRows = 16;
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 1.0;
  grid.height = 0.75;
  grid.origin = {-0.5, 0.5, 0.0};
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  SheetAndSphere scene;
  scene.world = std::make_unique<World>(WorldSettings{.threadCount = 1});
  scene.cloth = scene.world->createCloth(model, settings).value();
  RigidMotion motion;
  motion.pose.position = {0.0, 0.85, -0.35};
  motion.linearVelocity = {0.0, 0.0, 0.8};
  scene.sphere = scene.world->addCollider(Sphere::create(0.15, motion).value()).value();
  test::StepHealth health;
  for (int k = 0; k < 45; ++k) health(scene.world->step(1.0 / 60.0));  // centre reaches z = +0.25
  health.expectHealthy("sphere pushing the sheet");
  return scene;
}

TEST(ColliderSliding, AWithdrawingSphereLeavesTheSheetAsIfItHadVanished) {
  // Twin runs from the same pushed state: in one the sphere pulls back at 4 m/s, far faster
  // than the sheet swings back; in the other it simply disappears. A contact that may only
  // push cannot hold the sheet, so both sheets must swing back alike. One that may pull drags
  // the sheet back with the sphere.
  SheetAndSphere withdrawn = pushedSheet();
  SheetAndSphere vanished = pushedSheet();
  Real pushed = 0;
  for (const Vec3& x : withdrawn.world->positions(withdrawn.cloth).value()) {
    pushed = std::max(pushed, x.z());
  }
  ASSERT_GT(pushed, 0.1) << "the sphere should have pushed the sheet forward";

  RigidMotion motion = weft::motion(*withdrawn.world->collider(withdrawn.sphere).value());
  motion.linearVelocity = {0.0, 0.0, -4.0};
  ASSERT_TRUE(withdrawn.world->setColliderMotion(withdrawn.sphere, motion).ok());
  ASSERT_TRUE(vanished.world->destroyCollider(vanished.sphere).ok());
  Real largestGap = 0;
  test::StepHealth health;
  for (int k = 0; k < 20; ++k) {
    health(withdrawn.world->step(1.0 / 60.0));
    health(vanished.world->step(1.0 / 60.0));
    const std::span<const Vec3> a = withdrawn.world->positions(withdrawn.cloth).value();
    const std::span<const Vec3> b = vanished.world->positions(vanished.cloth).value();
    for (std::size_t i = 0; i < a.size(); ++i) largestGap = std::max(largestGap, (a[i] - b[i]).norm());
  }
  EXPECT_LT(largestGap, 0.01) << "m: the withdrawing sphere dragged the sheet";
  health.expectHealthy("withdrawing sphere");
}

TEST(ColliderSliding, ClothLyingOnTheFloorLiftsOffWhenPulledUp) {
  // A sheet lying on the floor, one edge pinned and yanked up 1.5 m in half a second: floor
  // contacts must let go of the rows the edge pulls up instead of holding them down and
  // stretching the edge between them.
  constexpr Index kColumns = 11, kRows = 11;
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 0.5;
  grid.height = 0.5;
  grid.origin = {-0.25, ClothMaterial{}.thickness, -0.25};  // resting on the floor
  grid.widthAxis = {1.0, 0.0, 0.0};
  grid.heightAxis = {0.0, 0.0, 1.0};
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  World world(WorldSettings{.threadCount = 1});
  ASSERT_TRUE(world.addCollider(Plane::create({0.0, 1.0, 0.0}).value()).ok());
  const ClothId cloth = world.createCloth(model, settings).value();
  // Let gravity press it onto the floor first.
  test::StepHealth health;
  Real maxStrain = 0;
  for (int k = 0; k < 30; ++k) health(world.step(1.0 / 60.0));
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (int k = 0; k < 30; ++k) {
    for (Vec3& target : targets) target.y() += 0.05;
    ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
    health(world.step(1.0 / 60.0));
    maxStrain = std::max(maxStrain, world.stats().maxStrain);
  }
  health.expectHealthy("sheet pulled off the floor");
  const std::span<const Vec3> x = world.positions(cloth).value();
  // The row next to the lifted one hangs below it by about one spacing, not on the floor.
  const Index nextRow = (kRows - 2) * kColumns + kColumns / 2;
  EXPECT_GT(x[nextRow].y(), 1.5 - 2 * 0.05);
  // Off the floor and carried up at a steady 3 m/s, the sheet hangs from its pinned edge: its
  // strain is at most twice the static strain under that edge, ρ_A g H / k. (The default
  // material has no strain limit, and the yank's first frames, pins stepping one edge length a
  // frame from rest, stretch it as much with the floor as without it: not bounded here.)
  const ClothMaterial material;
  const Real hanging = 2 * material.arealDensity * 9.81 * grid.height / material.weftStretchStiffness;
  std::printf("[sliding] sheet pulled off the floor: max strain %.4f over the lift, %.4f at its end "
              "(bound %.4f)\n", maxStrain, world.stats().maxStrain, hanging);
  EXPECT_LT(world.stats().maxStrain, hanging);
}

}  // namespace
}  // namespace weft
