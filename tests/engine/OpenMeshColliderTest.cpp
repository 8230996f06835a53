// Cloth against open triangle meshes (a one-quad table top, a single triangle): an open mesh is
// a two-sided shell (TriangleMeshShape::isClosed), so a cloth is kept at its thickness on
// whichever side it is. A cloth dropped on a table top drapes over it without gaining energy;
// one dropped on a single triangle is not torn; one rising from below a quad stops below it.
#include "ContactTestSupport.h"

#include <weft/collision/TriangleMeshShape.h>
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace weft {
namespace {

constexpr Real kFrame = 1.0 / 60.0;

// A horizontal square [−h, h]² at height y, two triangles facing up: open, one-sided in shape.
TriangleMeshShape tableTop(Real h, Real y) {
  const std::vector<Vec3> vertices = {Vec3(-h, y, h), Vec3(h, y, h), Vec3(h, y, -h),
                                      Vec3(-h, y, -h)};
  const std::vector<Index> indices = {0, 1, 2, 0, 2, 3};
  return TriangleMeshShape::create(vertices, indices).value();
}

// Kinetic plus gravitational potential energy (J) of the world's one cloth.
Real totalEnergy(const World& world, ClothId cloth, const std::vector<Real>& masses) {
  const std::span<const Vec3> x = world.positions(cloth).value();
  Real potential = 0;
  for (std::size_t i = 0; i < x.size(); ++i) potential += masses[i] * 9.81 * x[i].y();
  return world.stats().kineticEnergy + potential;
}

TEST(OpenMeshCollider, AClothDrapesOverAOneQuadTableTop) {
  // A 0.8 m cloth 0.15 m above a 0.5 m table top at 0.4 m.
  constexpr Real kTop = 0.4, kDrop = 0.55;
  World world;
  const TriangleMeshShape top = tableTop(0.25, kTop);
  ASSERT_FALSE(top.isClosed());
  const ColliderId collider = world.addCollider(top).value();
  const auto model = test::horizontalSquare(21, 0.8, kDrop);
  const ClothId cloth = world.createCloth(model, ClothSettings{}).value();
  const std::vector<Real> masses = model->vertexMasses(ClothMaterial{}.arealDensity);
  test::IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  const Real startEnergy = totalEnergy(world, cloth, masses);
  Real highest = -1;
  for (int frame = 0; frame < 180; ++frame) {
    health(world.step(kFrame));
    // No collider adds energy: gravity's work is all the cloth gets (1 mJ of 0.14 J dropped).
    ASSERT_LE(totalEnergy(world, cloth, masses), startEnergy + 1e-3) << "frame " << frame;
    for (const Vec3& x : world.positions(cloth).value()) highest = std::max(highest, x.y());
    ASSERT_LE(highest, kDrop + 1e-6) << "the cloth rose above its drop height, frame " << frame;
    ASSERT_GE(test::closestApproach(world, cloth, collider), 0.0) << "frame " << frame;
    ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
  }
  health.expectHealthy("table top");
  // Resting on the top: the centre at the thickness over it, the corners hanging below it.
  const std::span<const Vec3> x = world.positions(cloth).value();
  const Real thickness = ClothMaterial{}.thickness;
  EXPECT_NEAR(x[10 * 21 + 10].y(), kTop + thickness, 0.5 * thickness);
  for (Index corner : {0u, 20u, 20u * 21u, 21u * 21u - 1u}) {
    EXPECT_LT(x[corner].y(), kTop - 0.05) << "corner " << corner;
  }
}

TEST(OpenMeshCollider, AClothDroppedOnOneTriangleIsNotTorn) {
  World world;
  const std::vector<Vec3> vertices = {Vec3(-0.2, 0.3, 0.15), Vec3(0.2, 0.3, 0.15),
                                      Vec3(0, 0.3, -0.25)};
  const TriangleMeshShape triangle =
      TriangleMeshShape::create(vertices, std::vector<Index>{0, 1, 2}).value();
  const ColliderId collider = world.addCollider(triangle).value();
  ClothSettings settings;
  settings.material = cottonFabric();
  const Real limit = settings.material.strainLimit;
  ASSERT_GT(limit, 0);
  const ClothId cloth = world.createCloth(test::horizontalSquare(21, 0.8, 0.45), settings).value();
  test::StepHealth health;
  Real worst = 0;
  for (int frame = 0; frame < 150; ++frame) {
    health(world.step(kFrame));
    worst = std::max(worst, world.stats().maxStrain);
    ASSERT_LE(world.stats().maxStrain, limit + 0.01) << "frame " << frame;
    ASSERT_GE(test::closestApproach(world, cloth, collider), 0.0) << "frame " << frame;
  }
  health.expectHealthy("one triangle");
  // It landed on the triangle: the point over the triangle's centroid rests on it.
  const std::span<const Vec3> x = world.positions(cloth).value();
  const Real lowest = std::min_element(x.begin(), x.end(), [](const Vec3& a, const Vec3& b) {
                        return a.y() < b.y();
                      })->y();
  EXPECT_LT(lowest, 0.3 - 0.1) << "the cloth should hang round the triangle (max strain " << worst
                               << ")";
}

TEST(OpenMeshCollider, AClothRisingFromBelowAQuadStopsBelowIt) {
  // Gravity up: the cloth starts 0.15 m under the quad and is pressed up against its underside.
  constexpr Real kTop = 0.4;
  WorldSettings worldSettings;
  worldSettings.gravity = Vec3(0, 9.81, 0);
  World world(worldSettings);
  const ColliderId collider = world.addCollider(tableTop(0.25, kTop)).value();
  const ClothId cloth =
      world.createCloth(test::horizontalSquare(21, 0.8, kTop - 0.15), ClothSettings{}).value();
  test::IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  const Real thickness = ClothMaterial{}.thickness;
  // The vertices that start under the quad, 6 cm or more in from its edges (the flaps outside
  // it may rise past its edges and fold over it).
  std::vector<Index> under;
  const std::span<const Vec3> start = world.positions(cloth).value();
  for (Index i = 0; i < Index(start.size()); ++i) {
    if (std::abs(start[i].x()) < 0.19 && std::abs(start[i].z()) < 0.19) under.push_back(i);
  }
  ASSERT_EQ(under.size(), 81u);  // 9 × 9 of the 21 × 21 grid (4 cm apart)
  for (int frame = 0; frame < 120; ++frame) {
    health(world.step(kFrame));
    ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
    ASSERT_GE(test::closestApproach(world, cloth, collider), 0.0) << "frame " << frame;
    // They stay below it (by the thickness, to the pressed shell).
    const std::span<const Vec3> x = world.positions(cloth).value();
    for (Index i : under) {
      ASSERT_LT(x[i].y(), kTop - 0.5 * thickness) << "vertex " << i << " went through, frame "
                                                   << frame;
    }
  }
  health.expectHealthy("from below");
  // Pressed against the underside: the centre at the thickness below it.
  const std::span<const Vec3> x = world.positions(cloth).value();
  EXPECT_NEAR(x[10 * 21 + 10].y(), kTop - thickness, 0.5 * thickness);
}

}  // namespace
}  // namespace weft
