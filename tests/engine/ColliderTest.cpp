// Cloth against kinematic colliders: resting on a sphere and a floor, friction from a spinning
// sphere, and a drape over a triangle mesh that is the same on any thread count (fast
// projectiles: FastBodyTest.cpp). In every frame of the first three scenes no vertex is inside a
// collider and no two triangles of the cloth intersect (exact test).
#include "ContactTestSupport.h"
#include "collision/CollisionTestSupport.h"

#include <weft/collision/TriangleMeshShape.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

namespace weft {
namespace {

constexpr Real kFrame = 1.0 / 60.0;

std::shared_ptr<const ClothModel> square(Index vertices, Real size, Real height) {
  return test::horizontalSquare(vertices, size, height);
}

using test::closestApproach;

// Steps one frame and checks the contracts of every frame: no vertex inside the collider, no
// intersecting triangle pair; `health` records rollbacks and retries.
void stepChecked(World& world, ClothId cloth, ColliderId collider, test::IntersectionCounter& counter,
                 test::StepHealth& health, int frame) {
  health(world.step(kFrame));
  ASSERT_GE(closestApproach(world, cloth, collider), 0.0) << "a vertex is inside, frame " << frame;
  ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
}

TEST(Collider, ClothDropsOntoASphereAndRestsOnIt) {
  World world;
  const ColliderId sphere = world.addCollider(Sphere::create(0.3).value()).value();
  const ClothId cloth = world.createCloth(square(21, 1.2, 0.5), ClothSettings{}).value();
  test::IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  const Real top = 0.3 + ClothMaterial{}.thickness;  // m, where the centre rests
  Real lateEnergy = 0;  // J, summed over frames 120..149
  bool landed = false;  // the centre has reached the top
  int leftTheTop = -1;  // the first frame after that with the centre more than 1 cm off it
  for (int frame = 0; frame < 300; ++frame) {
    stepChecked(world, cloth, sphere, counter, health, frame);
    ASSERT_EQ(world.stats().status, StepStatus::Ok) << "frame " << frame;
    const std::span<const Vec3> x = world.positions(cloth).value();
    const bool onTop = std::abs(x[10 * 21 + 10].y() - top) <= 0.01;
    if (landed && !onTop && leftTheTop < 0) leftTheTop = frame;
    landed = landed || onTop;
    if (frame >= 120 && frame < 150) lateEnergy += world.stats().kineticEnergy;
    if (frame == 149) {
      // Draped by 2.5 s: the corners hang below the equator, the cloth lies on the sphere.
      EXPECT_LT(x[0].y(), 0.0);
      EXPECT_GT(world.stats().contacts, 20u);
      // Nearly at rest: the corners, folded where they hang, keep touching themselves and the
      // self-contact response keeps them stirring at ~1 mJ (0.216 kg of cloth: ~0.1 m/s rms), so
      // the mean over half a second is bounded rather than one frame's value.
      EXPECT_LT(lateEnergy / 30, 2e-3);
    }
  }
  // Resting: the centre stays on top for the 5 s. Friction that acted on velocities only would
  // let a sticking contact move h v_t in the solve and the drape creep off; the contact
  // projection's friction moves positions, bounded by the normal separation and the solve's
  // contact impulse (DynamicSystem::receiveContactImpulses).
  EXPECT_TRUE(landed) << "the centre never reached the top of the sphere";
  EXPECT_EQ(leftTheTop, -1) << "the drape's centre left the top (more than 1 cm off it) at frame "
                            << leftTheTop;
}

TEST(Collider, ClothFallsOntoTheFloorAndStaysAboveIt) {
  World world;
  const ColliderId floor = world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  const ClothId cloth = world.createCloth(square(11, 0.5, 0.2), ClothSettings{}).value();
  test::IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  for (int frame = 0; frame < 90; ++frame) stepChecked(world, cloth, floor, counter, health, frame);
  health.expectHealthy("cloth on the floor");
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
    const ColliderId sphere = world.addCollider(Sphere::create(0.3, spinning).value(), collider).value();
    ClothSettings settings;
    settings.material.friction = 0.4;
    const ClothId cloth = world.createCloth(square(21, 1.0, 0.35), settings).value();
    test::IntersectionCounter counter(world, {cloth});
    test::StepHealth health;
    for (int frame = 0; frame < 120; ++frame) stepChecked(world, cloth, sphere, counter, health, frame);
    health.expectHealthy("spinning sphere");
    spins[withFriction] = spin(world, cloth) / world.velocities(cloth).value().size();
  }
  // The sphere's surface moves with ω × r, whose angular momentum about +y is positive.
  EXPECT_GT(spins[1], 1e-3) << "friction should drag the cloth round";
  EXPECT_LT(std::abs(spins[0]), 0.1 * std::abs(spins[1])) << "without friction it barely turns";
}

TEST(Collider, ADrapeOverAMeshIsBitwiseTheSameOnOneTwoAndEightThreads) {
  // 1,681 vertices and 3,200 faces over a 48-sided cylinder: the collider queries of many fixed
  // blocks of vertices and faces run on different threads, and the rim's edges make face
  // contacts. The state must not depend on which thread ran which block.
  struct Drape {
    std::uint64_t hash = 0;
    Index vertexContacts = 0;  // at the last frame
    Index faceContacts = 0;    // over all frames
  };
  const auto drape = [](int threads) {
    WorldSettings worldSettings;
    worldSettings.threadCount = threads;
    World world(worldSettings);
    const test::MeshArrays post = test::makeCylinder(0.3, 0.3, 48);
    (void)world.addCollider(TriangleMeshShape::create(post.positions, post.indices).value()).value();
    (void)world.createCloth(square(41, 1.2, 0.45), ClothSettings{}).value();
    Drape result;
    for (int frame = 0; frame < 40; ++frame) {
      EXPECT_EQ(world.step(kFrame), StepStatus::Ok) << threads << " threads, frame " << frame;
      result.faceContacts += world.stats().faceContacts;
    }
    result.vertexContacts = world.stats().contacts;
    result.hash = world.stateHash();
    return result;
  };
  const Drape one = drape(1);
  EXPECT_GT(one.vertexContacts, 100u) << "the cloth no longer lies on the cylinder's top";
  EXPECT_GT(one.faceContacts, 0u) << "no face met the rim: the faces' mesh path is not tested";
  for (int threads : {2, 8}) {
    const Drape other = drape(threads);
    EXPECT_EQ(other.hash, one.hash) << threads << " threads";
    EXPECT_EQ(other.faceContacts, one.faceContacts) << threads << " threads";
  }
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
