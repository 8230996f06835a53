// Stress scenes with colliders and contact:
//
//   6  a cloth dropped on a sphere that spins at 3 rad/s, friction 0.4 (cloth and sphere);
//   7  three stacked sheets pushed by a sphere through a ring of 16 capsules (a funnel's neck);
//   8  a sphere at 250 m/s into a sheet pinned on all four sides: it crosses the sheet's plane
//      within its first frame and stops 10 cm beyond it, and the sheet must stay in front of it
//      (no tunnelling);
//   9  heavy objects dropped on a sheet pinned at its corners.
//
// The several sheets of scene 7, and the heavy objects and sheet of scene 9, are ONE ClothModel
// made of disconnected layers (ClothModel::fromMesh), kept apart by the self-collision; they were
// written before cloth–cloth collision between different cloths landed (World runs it after every
// cloth has stepped, ClothClothCollision.h) and still test the self-collision path. The heavy
// objects are small cloth pads (4 × 4 vertices, 12 cm) weighing 0.5 kg each, more than three
// times the sheet (ClothSettings::vertexMasses): colliders are kinematic, so a weight the sheet
// has to carry must be cloth.
#include "engine/ContactTestSupport.h"
#include "stress/StressSupport.h"

#include <cmath>
#include <limits>
#include <numbers>

namespace weft::stress {
namespace {

constexpr Real kFrame = 1.0 / 60.0;

using test::appendHorizontalSquare;
using test::closestApproach;

TEST(StressContact, ClothOnASpinningSphereWithFriction) {
  World world;
  RigidMotion spinning;
  spinning.angularVelocity = Vec3(0, 3.0, 0);
  ColliderSettings colliderSettings;
  colliderSettings.friction = 0.4;
  const ColliderId sphere =
      world.addCollider(Sphere::create(0.3, spinning).value(), colliderSettings).value();
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  settings.material.friction = 0.4;
  auto model = horizontalSquare(21, 1.0, 0.35);
  const ClothId cloth = world.createCloth(model, settings).value();
  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  for (int frame = 0; frame < 150; ++frame) {
    if (!monitor.afterFrame(world.step(kFrame))) break;
    ASSERT_GE(closestApproach(world, cloth, sphere), 0.0) << "frame " << frame;
  }
  // Friction turned the cloth with the sphere (angular momentum about +y is positive).
  const std::span<const Vec3> x = world.positions(cloth).value();
  const std::span<const Vec3> v = world.velocities(cloth).value();
  Real spin = 0;
  for (std::size_t i = 0; i < x.size(); ++i) spin += x[i].z() * v[i].x() - x[i].x() * v[i].z();
  EXPECT_GT(spin, 0.0);
  // Max strain 0.101 (0.213 when the limiter ran only before the collider response, whose
  // friction then stretched the cloth; 0.357 without the limiter): the limiter runs again after
  // the response, with the vertices on the sphere held along its normal (Cloth.cpp,
  // limitStrainInContact).
  monitor.expectPasses("spinning_sphere", kCottonStrainLimit);
}

TEST(StressContact, ThreeStackedSheetsPushedThroughARing) {
  TriangleMesh mesh;
  for (int layer = 0; layer < 3; ++layer) appendHorizontalSquare(mesh, 11, 0.5, Vec3(0, 0.5 + 0.01 * layer, 0));
  auto model = std::make_shared<const ClothModel>(ClothModel::fromMesh(mesh).value());
  World world;
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  const ClothId cloth = world.createCloth(model, settings).value();

  // The ring: 16 capsules (radius 2 cm) on a circle of radius 0.2 m at y = 0.3.
  constexpr int kSegments = 16;
  constexpr Real kRingRadius = 0.2, kTubeRadius = 0.02;
  const Real halfAngle = std::numbers::pi / kSegments;
  for (int k = 0; k < kSegments; ++k) {
    const Real angle = 2 * halfAngle * k + halfAngle;
    RigidMotion pose;
    pose.pose.position = kRingRadius * std::cos(halfAngle) * Vec3(std::cos(angle), 0, std::sin(angle)) +
                         Vec3(0, 0.3, 0);
    pose.pose.rotation = Quat::FromTwoVectors(Vec3::UnitY(), Vec3(-std::sin(angle), 0, std::cos(angle)));
    ASSERT_TRUE(world.addCollider(Capsule::create(kTubeRadius, kRingRadius * std::sin(halfAngle), pose).value()).ok());
  }
  // The pusher: a 8 cm sphere coming down the ring's axis at 0.6 m/s, from above the stack to
  // 0.6 m below the ring, then still.
  RigidMotion pusher;
  pusher.pose.position = Vec3(0, 0.65, 0);
  pusher.linearVelocity = Vec3(0, -0.6, 0);
  const ColliderId sphere = world.addCollider(Sphere::create(0.08, pusher).value()).value();

  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  Real deepest = 0;  // m, deepest any vertex went into the pusher
  for (int frame = 0; frame < 150; ++frame) {
    if (frame == 100) {
      RigidMotion still = motion(*world.collider(sphere).value());
      still.linearVelocity = Vec3::Zero();
      ASSERT_TRUE(world.setColliderMotion(sphere, still).ok());
    }
    if (!monitor.afterFrame(world.step(kFrame))) break;
    deepest = std::min(deepest, closestApproach(world, cloth, sphere));
  }
  std::printf("[stress] stacked sheets: deepest vertex %.2e m inside the pusher\n", -deepest);
  // The stack went through: every sheet's centre vertex is below the ring.
  const std::span<const Vec3> x = world.positions(cloth).value();
  for (int layer = 0; layer < 3; ++layer) EXPECT_LT(x[layer * 121 + 60].y(), 0.3) << "sheet " << layer;
  // The collider response follows each vertex's path relative to the body, and the
  // self-collision's clamp uses the same test, so no layer is pushed back into the pusher.
  EXPECT_GE(deepest, 0.0) << "a vertex went into the pusher sphere";
  monitor.expectPasses("stacked_sheets_through_ring", kCottonStrainLimit,
                       {{StressMonitor::Condition::Strain,
                         "measured 0.79 (2,168 edge-substeps the limiter left over). Until "
                         "2026-11-22 the ring's capsules (2 cm radius, under 5 cm edges) passed "
                         "between the vertices: the worst edges ran straight through a capsule, "
                         "a face reached a capsule's core in 33 ... 44 of the 150 frames, and the "
                         "scene measured 0.28 ... 0.34 over layers shifted by 0 ... 1e-5 m (0.29 "
                         "... 0.50 before, 3.0 ... 3.2 at 16 x 16 vertices a layer). With the "
                         "faces kept out of the colliders (ColliderFaceContacts) the sheets "
                         "catch on the ring instead of passing through it, and the sphere drags "
                         "them over it: 0.79 ... 4.7 over the same shifts, 3.0 ... 4.5 at 16 x "
                         "16; at frame ends faces are still 12 mm to 2 cm into a capsule, pushed "
                         "there by the self-collision pass that keeps the last word. So the "
                         "scene needs a joint end-of-step projection of collider contacts (faces "
                         "and vertices), self-contacts and edge limits. Earlier findings (before "
                         "the face contacts): not the solve's accuracy (every substep from the "
                         "first contact on is hard; the residual 1e-3 everywhere gave 0.27 ... "
                         "0.66), not friction (0.41 with every coefficient 0), not the limiter's "
                         "iterations (512 instead of 64 changed nothing). Tried and not kept: "
                         "vertices on two capsules sliding along their crease (0.21 ... 0.78), "
                         "every self-contact held in the limiter (0.26 ... 0.50; with the face "
                         "contacts 0.56 ... 3.9, measured with their first version), self-"
                         "contacts held along the pass's direction "
                         "(0.81), one-sided collider holds (1.6 ... 5.9; with the face contacts "
                         "3.3 and a blow-up); the self-collision pass treating the vertices in "
                         "collider contact (vertex and face holds of the substep) as held "
                         "(2026-11-23: immovable 1.7 as written; held along the normal 1.2 as "
                         "written, 0.86 ... 17 shifted; held only where the impulse would push "
                         "them in 3.8 ... 7.3 over the shifts, 14.7 at 16 x 16; with impact zones "
                         "following the held vertices, throws capped, a regularised normal, or "
                         "the collider passes last: 1.9 ... 23, some runs over 10 times slower): "
                         "it keeps the faces out of the ring as written, but the free side of a "
                         "pair takes the whole impulse, vertices with small weights are thrown, "
                         "and the strain does not come down"}});
}

TEST(StressContact, SphereAt250MetresPerSecondDoesNotTunnelThroughAPinnedSheet) {
  constexpr Index kVertices = 21;
  GridSettings grid;
  grid.columns = grid.rows = kVertices;
  grid.width = grid.height = 1.0;
  grid.origin = Vec3(-0.5, 0.5, 0);
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  for (Index k = 0; k < kVertices; ++k) {
    settings.pinnedVertices.push_back(k);                                  // bottom
    settings.pinnedVertices.push_back((kVertices - 1) * kVertices + k);    // top
    if (k > 0 && k + 1 < kVertices) {
      settings.pinnedVertices.push_back(k * kVertices);                    // left
      settings.pinnedVertices.push_back(k * kVertices + kVertices - 1);    // right
    }
  }
  World world;
  const ClothId cloth = world.createCloth(model, settings).value();
  constexpr Real kRadius = 0.1, kSpeed = 250;
  RigidMotion projectile;
  // It ends its first frame with its centre in the sheet's plane: 10 cm of it beyond.
  projectile.pose.position = Vec3(0, 1.0, -kSpeed * kFrame);
  projectile.linearVelocity = Vec3(0, 0, kSpeed);
  const ColliderId sphere = world.addCollider(Sphere::create(kRadius, projectile).value()).value();
  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  int tunnelledAt = -1;
  for (int frame = 0; frame < 90; ++frame) {
    if (frame == 1) {
      RigidMotion stopped = motion(*world.collider(sphere).value());
      EXPECT_NEAR(stopped.pose.position.z(), 0.0, 1e-9);
      stopped.linearVelocity = Vec3::Zero();
      ASSERT_TRUE(world.setColliderMotion(sphere, stopped).ok());
    }
    if (!monitor.afterFrame(world.step(kFrame))) break;
    // No vertex inside the sphere, and the sheet's middle in front of it, not behind or beside.
    const bool inFront = closestApproach(world, cloth, sphere) >= 0.0 &&
                         world.positions(cloth).value()[10 * kVertices + 10].z() > kRadius - 1e-3;
    if (!inFront && tunnelledAt < 0) tunnelledAt = frame;
  }
  std::printf("[stress] 250 m/s sphere: sheet %s (first frame behind: %d)\n",
              tunnelledAt < 0 ? "stayed in front" : "TUNNELLED", tunnelledAt);
  // The collider response follows each vertex's path relative to the body (the face it meets,
  // not the nearest face at the end pose), in the solve's constraints and after the step.
  EXPECT_LT(tunnelledAt, 0) << "the sheet must stay in front of the 250 m/s sphere";
  // Max strain 0.107 (0.80 at the impact when the limiter ran only before the collider
  // response). Contact with colliders is per vertex, so with a 5 cm grid on a 10 cm sphere the
  // edges between vertices on the sphere and vertices beside it still cut into it; the limiter
  // run after the response slides the vertices on the sphere (held along its normal) and pulls
  // the others in, and the response has the last word again.
  monitor.expectPasses("sphere_250_m_per_s", kCottonStrainLimit);
}

TEST(StressContact, HeavyObjectsDroppedOnASheetPinnedAtItsCorners) {
  constexpr Index kSheet = 15, kPad = 4;
  TriangleMesh mesh;
  appendHorizontalSquare(mesh, kSheet, 1.0, Vec3(0, 1.0, 0));
  const Index firstPad = appendHorizontalSquare(mesh, kPad, 0.12, Vec3(-0.2, 1.25, 0.1));
  const Index secondPad = appendHorizontalSquare(mesh, kPad, 0.12, Vec3(0.15, 1.4, -0.15));
  auto model = std::make_shared<const ClothModel>(ClothModel::fromMesh(mesh).value());
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  settings.vertexMasses = model->vertexMasses(settings.material.arealDensity);
  constexpr Real kObjectMass = 0.5;  // kg each; the sheet weighs 0.15 kg
  for (Index pad : {firstPad, secondPad}) {
    for (Index i = 0; i < kPad * kPad; ++i) settings.vertexMasses[pad + i] = kObjectMass / (kPad * kPad);
  }
  // Pinned at its corners: the 2 × 2 vertices of each corner.
  for (Index row : {0u, 1u, kSheet - 2, kSheet - 1}) {
    for (Index column : {0u, 1u, kSheet - 2, kSheet - 1}) settings.pinnedVertices.push_back(row * kSheet + column);
  }
  World world;
  const ClothId cloth = world.createCloth(model, settings).value();
  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  for (int frame = 0; frame < 150; ++frame) {
    if (!monitor.afterFrame(world.step(kFrame))) break;
  }
  // The objects landed (below where they started) and rest on the sheet: above the lowest
  // sheet vertex, not through it.
  const std::span<const Vec3> x = world.positions(cloth).value();
  Real lowestSheet = std::numeric_limits<Real>::infinity();
  for (Index i = 0; i < kSheet * kSheet; ++i) lowestSheet = std::min(lowestSheet, x[i].y());
  EXPECT_LT(x[firstPad].y(), 1.25);
  std::printf("[stress] heavy objects: pad corners at y = %.3f and %.3f, lowest sheet vertex %.3f\n",
              x[firstPad].y(), x[secondPad].y(), lowestSheet);
  EXPECT_GT(x[firstPad].y(), lowestSheet);
  EXPECT_GT(x[secondPad].y(), lowestSheet);
  // Max strain 0.103 (8.1 before the self-contacts were held inside the limiter; 32 when the
  // limiter ran only before the collisions, 45 without it). The pads touch the sheet only through
  // the self-collision, which hands their momentum to the light sheet vertices under them; the
  // limiter run after it holds those pairs apart (StrainLimiter::applyInContact, `separations`)
  // with both sides counting as heavy as the pad, so lifting the sheet lifts the pads with it.
  monitor.expectPasses("heavy_objects_on_sheet", kCottonStrainLimit);
}

}  // namespace
}  // namespace weft::stress
