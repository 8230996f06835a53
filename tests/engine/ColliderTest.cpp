// Cloth against kinematic colliders: resting on a sphere and a floor, friction from a spinning
// sphere, and a fast projectile that must not tunnel. In every frame of every scene no vertex
// is inside a collider.
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <cmath>

namespace weft {
namespace {

constexpr Real kFrame = 1.0 / 60.0;

std::shared_ptr<const ClothModel> square(Index vertices, Real size, Real height) {
  GridSettings grid;
  grid.columns = vertices;
  grid.rows = vertices;
  grid.width = size;
  grid.height = size;
  // Horizontal: rows run along −z, so the front faces +y.
  grid.origin = Vec3(-size / 2, height, size / 2);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

// Smallest signed distance of any cloth vertex to a collider.
Real closestApproach(const World& world, ClothId cloth, ColliderId collider) {
  const Shape* shape = world.collider(collider).value();
  Real closest = std::numeric_limits<Real>::infinity();
  for (const Vec3& x : world.positions(cloth).value()) {
    closest = std::min(closest, queryPoint(*shape, x).distance);
  }
  return closest;
}

TEST(Collider, ClothDropsOntoASphereAndRestsOnIt) {
  World world;
  const ColliderId sphere = world.addCollider(Sphere::create(0.3).value()).value();
  const ClothId cloth = world.createCloth(square(21, 1.2, 0.5), ClothSettings{}).value();
  for (int frame = 0; frame < 150; ++frame) {
    ASSERT_EQ(world.step(kFrame), StepStatus::Ok) << "frame " << frame;
    ASSERT_GE(closestApproach(world, cloth, sphere), 0.0) << "a vertex is inside, frame " << frame;
  }
  const std::span<const Vec3> x = world.positions(cloth).value();
  const Vec3& centre = x[10 * 21 + 10];
  // Draped: the centre sits on top of the sphere, the corners hang below its equator.
  EXPECT_NEAR(centre.y(), 0.3 + ClothMaterial{}.thickness, 0.01);
  EXPECT_LT(x[0].y(), 0.0);
  EXPECT_GT(world.stats().contacts, 20u);
  // Nearly at rest: the drop releases ~0.5 J. Both bending models leave 0.9–1.3 mJ of slow creep
  // at frame 150, and the drape does not stay put: run on, it slides off the sphere (after
  // ~frame 250 with dihedral bending, ~330 with isometric), an open collision/friction issue.
  EXPECT_LT(world.stats().kineticEnergy, 2e-3);
}

TEST(Collider, ClothFallsOntoTheFloorAndStaysAboveIt) {
  World world;
  const ColliderId floor = world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  const ClothId cloth = world.createCloth(square(11, 0.5, 0.2), ClothSettings{}).value();
  for (int frame = 0; frame < 90; ++frame) {
    world.step(kFrame);
    ASSERT_GE(closestApproach(world, cloth, floor), 0.0) << "frame " << frame;
  }
  for (const Vec3& x : world.positions(cloth).value()) EXPECT_NEAR(x.y(), 0.003, 1e-3);
}

// Angular momentum about the vertical axis through the origin, L_y = z·v_x − x·v_z, per unit mass.
Real spin(const World& world, ClothId cloth) {
  const std::span<const Vec3> x = world.positions(cloth).value();
  const std::span<const Vec3> v = world.velocities(cloth).value();
  Real momentum = 0;
  for (std::size_t i = 0; i < x.size(); ++i) momentum += x[i].z() * v[i].x() - x[i].x() * v[i].z();
  return momentum;
}

TEST(Collider, FrictionOfASpinningSphereDragsTheCloth) {
  Real spins[2];
  for (int withFriction = 0; withFriction < 2; ++withFriction) {
    World world;
    RigidMotion spinning;
    spinning.angularVelocity = Vec3(0, 3.0, 0);  // rad/s about +y
    ColliderSettings collider;
    collider.friction = withFriction ? 0.4 : 0.0;
    (void)world.addCollider(Sphere::create(0.3, spinning).value(), collider).value();
    ClothSettings settings;
    settings.material.friction = 0.4;
    const ClothId cloth = world.createCloth(square(21, 1.0, 0.35), settings).value();
    for (int frame = 0; frame < 120; ++frame) world.step(kFrame);
    spins[withFriction] = spin(world, cloth) / world.velocities(cloth).value().size();
  }
  // The sphere's surface moves with ω × r, whose angular momentum about +y is positive.
  EXPECT_GT(spins[1], 1e-3) << "friction should drag the cloth round";
  EXPECT_LT(std::abs(spins[0]), 0.1 * std::abs(spins[1])) << "without friction it barely turns";
}

TEST(Collider, FastProjectileDoesNotTunnelThroughAPinnedSheet) {
  // A 10 cm sphere at 50 m/s crosses the sheet's plane within one frame (0.83 m per frame).
  World world;
  GridSettings grid;
  grid.columns = grid.rows = 21;
  grid.width = grid.height = 1.0;
  grid.origin = Vec3(-0.5, 0.5, 0);
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  for (Index c = 0; c < 21; ++c) {
    settings.pinnedVertices.push_back(c);
    settings.pinnedVertices.push_back(20 * 21 + c);
  }
  const ClothId cloth = world.createCloth(model, settings).value();
  RigidMotion projectile;
  projectile.pose.position = Vec3(0, 1.0, -1.0);
  projectile.linearVelocity = Vec3(0, 0, 50);
  const ColliderId sphere = world.addCollider(Sphere::create(0.1, projectile).value()).value();
  for (int frame = 0; frame < 3; ++frame) {
    world.step(kFrame);
    ASSERT_GE(closestApproach(world, cloth, sphere), 0.0) << "frame " << frame;
  }
  // The sphere is now 1.5 m past the sheet's plane; the sheet's middle went with it.
  const Real sphereZ = motion(*world.collider(sphere).value()).pose.position.z();
  EXPECT_GT(sphereZ, 1.4);
  const Vec3& middle = world.positions(cloth).value()[10 * 21 + 10];
  EXPECT_GT(middle.z(), sphereZ) << "the sheet must stay in front of the sphere";
}

TEST(Collider, HandlesGoStale) {
  World world;
  const ColliderId sphere = world.addCollider(Sphere::create(0.3).value()).value();
  EXPECT_TRUE(world.destroyCollider(sphere).ok());
  EXPECT_FALSE(world.collider(sphere).ok());
  EXPECT_FALSE(world.setColliderMotion(sphere, RigidMotion{}).ok());
  ColliderSettings bad;
  bad.friction = -1;
  EXPECT_FALSE(world.addCollider(Sphere::create(0.3).value(), bad).ok());
}

}  // namespace
}  // namespace weft
