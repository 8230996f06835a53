// The strain limiter with self-contacts held inside its iteration (StrainLimiter::applyInContact's
// `separations`, filled by the self-collision pass in Cloth::limitStrainInContact): a heavy
// vertex resting on a light triangle that hangs from pins, stretched. Without the hold the
// limiter lifts the triangle through the weight (the collisions after it then pushed the light
// triangle back down and stretched it again: stress scene 9). Then the same in a World.
#include "ContactTestSupport.h"
#include "StrainLimiting.h"
#include "StrainLimitingTestSupport.h"

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <vector>

namespace weft {
namespace {

using test::kStep;
using test::makeEdge;
constexpr Real kSeparation = 0.003;  // m, the cotton preset's thickness

// Pins 0, 1, 2 at y = 0; a light triangle 3, 4, 5 hanging 1.5 m below them on edges of rest
// length 1 (strain 0.5); a heavy vertex 6 resting on the triangle's centre, kSeparation above it.
struct HangingTriangle {
  std::vector<Edge> edges{makeEdge(0, 3, 1.0), makeEdge(1, 4, 1.0), makeEdge(2, 5, 1.0)};
  std::vector<Real> inverseMasses{0, 0, 0, 1000, 1000, 1000, 2};  // 1 g vertices, a 0.5 kg weight
  Vec3Array x{Vec3(0, 0, 0),     Vec3(0.3, 0, 0),     Vec3(0, 0, 0.3),    Vec3(0, -1.5, 0),
              Vec3(0.3, -1.5, 0), Vec3(0, -1.5, 0.3), Vec3(0.1, -1.5 + kSeparation, 0.1)};
  Vec3Array v = Vec3Array(7, Vec3::Zero());
  Vec3Array normals = Vec3Array(7, Vec3::Zero());
  // Vertex–triangle (6; 3, 4, 5) at barycentric (1/3, 1/3, 1/3), normal +y (from the triangle to
  // the vertex), kept at the separation the collisions left.
  std::vector<SeparationHold> holds{
      SeparationHold{{6, 3, 4, 5}, {1, -1.0 / 3, -1.0 / 3, -1.0 / 3}, Vec3(0, 1, 0), kSeparation}};

  Real gap() const { return x[6].y() - (x[3].y() + x[4].y() + x[5].y()) / 3; }
  Real maxStrain() const {
    Real strain = 0;
    for (const Edge& edge : edges) {
      strain = std::max(strain, (x[edge.vertices[1]] - x[edge.vertices[0]]).norm() / edge.restLength - 1);
    }
    return strain;
  }
};

TEST(StrainLimitingSelfContact, AHeavyVertexOnALightStretchedTriangleIsLiftedWithIt) {
  for (StrainLimitOrder order : {StrainLimitOrder::GaussSeidel, StrainLimitOrder::Jacobi}) {
    SCOPED_TRACE(order == StrainLimitOrder::GaussSeidel ? "Gauss-Seidel" : "Jacobi");
    TaskSystem tasks(TaskSystemSettings{2});
    HangingTriangle scene;
    StrainLimiter limiter(scene.edges, 7);
    const Vec3Array x0 = scene.x, v0 = scene.v;
    const StrainLimitReport report =
        limiter.applyInContact({.limit = 0.1, .order = order}, scene.inverseMasses, scene.normals,
                               kStep, scene.x, scene.v, tasks, scene.holds);
    // The triangle came up to the limit and carried the weight with it: still on top, within a
    // micrometre of its separation, not through it.
    EXPECT_EQ(report.edgesOverLimit, 0u);
    EXPECT_LE(scene.maxStrain(), 0.1 + 1e-3);
    EXPECT_GE(scene.gap(), kSeparation - 1e-6);
    EXPECT_GT(scene.x[6].y(), -1.2);  // lifted 0.3 m or more
    // Positions and velocities changed together (Δv = Δx / h); the pins did not move.
    for (int i = 0; i < 7; ++i) {
      EXPECT_NEAR(((scene.v[i] - v0[i]) * kStep - (scene.x[i] - x0[i])).norm(), 0, 1e-9);
    }
    for (int i = 0; i < 3; ++i) EXPECT_EQ(scene.x[i], x0[i]);
  }
}

TEST(StrainLimitingSelfContact, WithoutTheHoldTheTriangleIsLiftedThroughTheWeight) {
  // The same case without `separations` (the limiter before self-contacts were held): the
  // triangle passes through the weight, which stays where it was.
  TaskSystem tasks(TaskSystemSettings{1});
  HangingTriangle scene;
  StrainLimiter limiter(scene.edges, 7);
  const Vec3 weight = scene.x[6];
  (void)limiter.applyInContact({.limit = 0.1}, scene.inverseMasses, scene.normals, kStep, scene.x,
                               scene.v, tasks);
  EXPECT_LE(scene.maxStrain(), 0.1 + 1e-3);
  EXPECT_EQ(scene.x[6], weight);
  EXPECT_LT(scene.gap(), -0.3);
}

TEST(StrainLimitingSelfContact, APairAlreadyApartIsLeftAlone) {
  // A hold only pushes apart: a pair farther apart than its separation keeps its positions bit
  // for bit while the limiter works on the edges.
  TaskSystem tasks(TaskSystemSettings{1});
  HangingTriangle scene;
  scene.x[6].y() = 0.5;  // far above the triangle and above where it will end
  StrainLimiter limiter(scene.edges, 7);
  const Vec3 weight = scene.x[6];
  (void)limiter.applyInContact({.limit = 0.1}, scene.inverseMasses, scene.normals, kStep, scene.x,
                               scene.v, tasks, scene.holds);
  EXPECT_LE(scene.maxStrain(), 0.1 + 1e-3);
  EXPECT_EQ(scene.x[6], weight);
  EXPECT_EQ(scene.v[6], Vec3::Zero());
}

// In a World (Cloth::limitStrainInContact): a small heavy pad dropped on a light sheet pinned at
// its corners, one ClothModel, so the pad touches the sheet through the self-collision (stress
// scene 9, scaled down). The pad's pairs with the sheet are held inside the limiter.
Real heavyPadOnSheetMaxStrain() {
  TriangleMesh mesh;
  constexpr Index kSheet = 9, kPad = 3;
  test::appendHorizontalSquare(mesh, kSheet, 0.5, Vec3(0, 1.0, 0));
  const Index pad = test::appendHorizontalSquare(mesh, kPad, 0.08, Vec3(0.02, 1.05, -0.03));
  auto model = std::make_shared<const ClothModel>(ClothModel::fromMesh(mesh).value());
  ClothSettings settings;
  settings.material = cottonFabric();
  settings.vertexMasses = model->vertexMasses(settings.material.arealDensity);
  for (Index i = 0; i < kPad * kPad; ++i) settings.vertexMasses[pad + i] = 0.2 / (kPad * kPad);
  for (Index corner : {Index(0), kSheet - 1, kSheet * (kSheet - 1), kSheet * kSheet - 1}) {
    settings.pinnedVertices.push_back(corner);
  }
  World world;
  const ClothId cloth = world.createCloth(model, settings).value();
  Real maxStrain = 0;
  test::StepHealth health;
  for (int frame = 0; frame < 60; ++frame) {
    health(world.step(kStep));
    maxStrain = std::max(maxStrain, world.stats().maxStrain);
  }
  health.expectHealthy("heavy pad on a sheet");
  // The pad rests on the sheet, above its lowest vertex.
  const std::span<const Vec3> x = world.positions(cloth).value();
  Real lowestSheet = std::numeric_limits<Real>::infinity();
  for (Index i = 0; i < kSheet * kSheet; ++i) lowestSheet = std::min(lowestSheet, x[i].y());
  EXPECT_GT(x[pad + kPad * kPad / 2].y(), lowestSheet);
  return maxStrain;
}

TEST(StrainLimitingSelfContact, AHeavyPadOnALightPinnedSheetStaysWithinTheLimit) {
  const Real maxStrain = heavyPadOnSheetMaxStrain();
  std::printf("[strain] heavy pad on a pinned sheet: max strain %.4f\n", maxStrain);
  EXPECT_LE(maxStrain, 0.1 + 0.01);
}

}  // namespace
}  // namespace weft
