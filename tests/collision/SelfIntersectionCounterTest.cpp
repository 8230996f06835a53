// Intersection counting: zero on flat and gently deformed sheets, the known count of a crafted
// fold, and equality with the O(n²) exact count on crumpled meshes.
#include <weft/collision/SelfIntersectionCounter.h>

#include <weft/collision/TriangleIntersection.h>

#include "collision/CollisionTestSupport.h"

#include <gtest/gtest.h>

namespace weft {
namespace {

using test::MeshArrays;

std::vector<TrianglePair> bruteForceIntersections(const MeshArrays& mesh,
                                                  const std::vector<Vec3>& x) {
  std::vector<TrianglePair> pairs;
  for (Index i = 0; i < mesh.triangleCount(); ++i) {
    const auto a = mesh.triangle(i);
    for (Index j = i + 1; j < mesh.triangleCount(); ++j) {
      const auto b = mesh.triangle(j);
      if (test::shareVertex(a, b)) continue;
      if (trianglesIntersect(x[a[0]], x[a[1]], x[a[2]], x[b[0]], x[b[1]], x[b[2]])) {
        pairs.push_back({i, j});
      }
    }
  }
  return pairs;
}

SelfIntersectionCounter makeCounter(const MeshArrays& mesh) {
  Result<SelfIntersectionCounter> counter =
      SelfIntersectionCounter::create(mesh.indices, mesh.positions);
  EXPECT_TRUE(counter.ok()) << counter.error().message;
  return std::move(counter).value();
}

TEST(SelfIntersectionCounter, FlatAndSmoothSheetsHaveNone) {
  const MeshArrays mesh = test::makeGrid(20, 20, 0.05);
  SelfIntersectionCounter counter = makeCounter(mesh);
  // Flat: neighbouring triangles touch only at shared vertices (skipped), and coplanar
  // non-adjacent triangles do not overlap.
  EXPECT_EQ(counter.count(mesh.positions), 0u);
  std::vector<Vec3> wavy = mesh.positions;
  for (Vec3& x : wavy) x.z() = 0.05 * std::sin(6 * x.x()) * std::cos(4 * x.y());
  EXPECT_EQ(counter.count(wavy), 0u);
}

TEST(SelfIntersectionCounter, CraftedFoldThroughTheSheet) {
  // A 2-triangle flap (its own vertices) pushed through a flat 2-triangle quad. Coordinates are
  // dyadic, so every crossing point below is exact and nothing merely touches.
  MeshArrays mesh;
  mesh.positions = {Vec3(0, 0, 0),         Vec3(1, 0, 0),         Vec3(1, 1, 0),
                    Vec3(0, 1, 0),                                                  // quad
                    Vec3(0.25, 0.125, -3), Vec3(0.25, 0.875, -3), Vec3(0.75, 0.125, 1),
                    Vec3(0.75, 0.875, 1)};                                          // flap
  mesh.indices = {0, 1, 2, 0, 2, 3, 4, 6, 7, 4, 7, 5};
  SelfIntersectionCounter counter = makeCounter(mesh);
  std::vector<TrianglePair> pairs;
  counter.findIntersectingPairs(mesh.positions, pairs);
  // The flap crosses z = 0 along x = 0.625. Flap triangle 2 crosses it for y ∈ [0.125, 0.6875],
  // through the quad's diagonal y = x: it pierces both quad triangles. Flap triangle 3 crosses
  // for y ∈ [0.6875, 0.875], above the diagonal: only quad triangle 1 (y ≥ x).
  const std::vector<TrianglePair> expected = {{0, 2}, {1, 2}, {1, 3}};
  EXPECT_EQ(pairs, expected);
  EXPECT_EQ(counter.count(mesh.positions), 3u);
  // Lifted clear of the quad: none.
  std::vector<Vec3> lifted = mesh.positions;
  for (std::size_t v = 4; v < lifted.size(); ++v) lifted[v].z() += 3.5;
  EXPECT_EQ(counter.count(lifted), 0u);
}

TEST(SelfIntersectionCounter, EqualsBruteForceOnCrumpledMeshes) {
  const MeshArrays mesh = test::makeGrid(20, 20, 0.05);
  SelfIntersectionCounter counter = makeCounter(mesh);
  std::vector<TrianglePair> pairs;
  Index total = 0;
  for (unsigned seed = 0; seed < 4; ++seed) {
    const std::vector<Vec3> x = seed < 2 ? test::crumple(mesh.positions, 0.04, seed)
                                         : test::fold(mesh.positions, 0.08, 0.3, 0.02, seed);
    const std::vector<TrianglePair> expected = bruteForceIntersections(mesh, x);
    counter.findIntersectingPairs(x, pairs);
    EXPECT_EQ(pairs, expected) << "seed " << seed;
    EXPECT_EQ(counter.count(x), expected.size());
    total += static_cast<Index>(expected.size());
  }
  EXPECT_GT(total, 50u) << "the meshes should intersect themselves";
}

}  // namespace
}  // namespace weft
