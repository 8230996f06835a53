// Bvh::setRefitMargin: a refit keeps the boxes of parts that moved less than the margin, the
// boxes still bound their triangles, and every query returns exactly what a tree refit in full
// returns. Half of a crumpled sheet moves, the other half creeps by round-off.
#include <weft/collision/Bvh.h>

#include "collision/CollisionTestSupport.h"

#include <gtest/gtest.h>

#include <vector>

namespace weft {
namespace {

using test::MeshArrays;

Bvh buildTree(const MeshArrays& mesh) {
  Result<Bvh> tree = Bvh::build(mesh.indices, mesh.positions);
  EXPECT_TRUE(tree.ok()) << tree.error().message;
  return std::move(tree).value();
}

// True when some triangle under node n has a vertex in `moving`.
bool hasMovingTriangle(const Bvh& tree, Index n, const std::vector<char>& moving) {
  const Bvh::Node& node = tree.nodes()[n];
  if (!node.isLeaf()) {
    return hasMovingTriangle(tree, node.first, moving) ||
           hasMovingTriangle(tree, node.first + 1, moving);
  }
  for (Index t : tree.leafTriangles(node)) {
    for (Index v : tree.triangle(t)) {
      if (moving[v]) return true;
    }
  }
  return false;
}

// True when node n is a leaf whose triangles all have three moving vertices: its box moves as a
// whole, so it must be refit. (The nodes above it need not be: a still sibling may span it.)
bool isWhollyMovingLeaf(const Bvh& tree, Index n, const std::vector<char>& moving) {
  const Bvh::Node& node = tree.nodes()[n];
  if (!node.isLeaf()) return false;
  for (Index t : tree.leafTriangles(node)) {
    for (Index v : tree.triangle(t)) {
      if (!moving[v]) return false;
    }
  }
  return true;
}

// The positions of step k: a crumpled sheet (±2 cm, so the self query has work) whose right half
// (x > 1 m) rises by 5 cm a step, out of every box of the step before, while the left half
// creeps by 1e-9 m.
std::vector<Vec3> positionsAt(const std::vector<Vec3>& crumpled, const std::vector<char>& moving,
                              int step) {
  std::vector<Vec3> x = crumpled;
  for (std::size_t v = 0; v < x.size(); ++v) {
    x[v].z() += moving[v] ? 0.05 * step : 1e-9 * (step % 3);
  }
  return x;
}

TEST(BvhRefitSkip, TheStillHalfKeepsItsBoxesAndQueriesDoNotChange) {
  const MeshArrays mesh = test::makeGrid(41, 31, 0.05);  // x from 0 to 2 m
  const std::vector<Vec3> crumpled = test::crumple(mesh.positions, 0.02, 7);
  std::vector<char> moving(mesh.positions.size(), 0);
  for (std::size_t v = 0; v < moving.size(); ++v) moving[v] = mesh.positions[v].x() > 1.0;

  Bvh full = buildTree(mesh), skipping = buildTree(mesh);
  const Real margin = 0.0015;  // half a 3 mm thickness (the engine uses 60 µm)
  skipping.setRefitMargin(margin);
  const Index nodes = Index(full.nodes().size());
  // Nodes over moving triangles may need a refit (at most these are refit), leaves that move as
  // a whole do (at least these are). A leaf on the border whose still triangles still span the
  // moving ones' boxes keeps its box, rightly, and so may the nodes above it.
  Index mostRefits = 0, leastRefits = 0;
  for (Index n = 0; n < nodes; ++n) {
    mostRefits += hasMovingTriangle(full, n, moving);
    leastRefits += isWhollyMovingLeaf(full, n, moving);
  }
  ASSERT_GT(leastRefits, nodes / 8);
  ASSERT_LT(mostRefits, 3 * nodes / 4);

  std::vector<TrianglePair> fullPairs, skippingPairs;
  std::vector<Index> fullBox, skippingBox;
  std::vector<Vec3> previous = positionsAt(crumpled, moving, 0);
  for (int step = 1; step <= 8; ++step) {
    const std::vector<Vec3> current = positionsAt(crumpled, moving, step);
    // A static refit, then a swept one, both inflated by the thickness.
    for (int pass = 0; pass < 2; ++pass) {
      const Real inflate = 0.003;
      const std::vector<Vec3>& from = pass == 0 ? current : previous;
      full.refit(from, current, inflate);
      skipping.refit(from, current, inflate);
      EXPECT_EQ(full.lastRefitCounts().refitNodes, nodes);
      const Bvh::RefitCounts counts = skipping.lastRefitCounts();
      EXPECT_EQ(counts.refitNodes + counts.skippedNodes, nodes);
      // After the first refit (the rest shape's tight boxes are not the margin's) only the nodes
      // above moving triangles are refit.
      if (step > 1) {
        EXPECT_LE(counts.refitNodes, mostRefits) << "step " << step << " pass " << pass;
        EXPECT_GE(counts.refitNodes, leastRefits) << "step " << step << " pass " << pass;
      }
      // Every box still holds its subtree's exact boxes.
      for (Index n = 0; n < nodes; ++n) {
        const Aabb& exact = full.nodes()[n].bounds;
        const Aabb& kept = skipping.nodes()[n].bounds;
        ASSERT_TRUE((kept.min.array() <= exact.min.array()).all() &&
                    (kept.max.array() >= exact.max.array()).all())
            << "node " << n << " step " << step;
      }
      // The queries are exact: the same pairs and triangles, bit for bit.
      full.querySelf(fullPairs);
      skipping.querySelf(skippingPairs);
      ASSERT_GT(fullPairs.size(), 100u);
      EXPECT_EQ(skippingPairs, fullPairs) << "step " << step;
      const Aabb probe{Vec3(0.2, 0.3, -0.2), Vec3(0.35, 0.6, 0.2)};
      full.queryBox(probe, fullBox);
      skipping.queryBox(probe, skippingBox);
      EXPECT_EQ(skippingBox, fullBox);
      full.queryPairs(full, fullPairs);
      skipping.queryPairs(skipping, skippingPairs);
      EXPECT_EQ(skippingPairs, fullPairs);
    }
    previous = current;
  }
}

TEST(BvhRefitSkip, MarginZeroSkipsOnlyUnchangedBoxesAndTwoThreadsAgree) {
  const MeshArrays mesh = test::makeGrid(41, 31, 0.05);
  const std::vector<Vec3> x = test::fold(mesh.positions, 0.1, 0.5, 0.01, 3);
  Bvh full = buildTree(mesh), serial = buildTree(mesh), parallel = buildTree(mesh);
  serial.setRefitMargin(0);
  parallel.setRefitMargin(0);
  TaskSystem tasks(TaskSystemSettings{2});
  full.refit(x, x, 0.003);
  serial.refit(x, x, 0.003);
  parallel.refit(x, x, 0.003, &tasks);
  // Unchanged positions: nothing to recompute, and the boxes are those of a full refit.
  serial.refit(x, x, 0.003);
  parallel.refit(x, x, 0.003, &tasks);
  EXPECT_EQ(serial.lastRefitCounts().refitNodes, 0u);
  EXPECT_EQ(parallel.lastRefitCounts().refitNodes, 0u);
  for (std::size_t n = 0; n < full.nodes().size(); ++n) {
    ASSERT_EQ(serial.nodes()[n].bounds, full.nodes()[n].bounds);
    ASSERT_EQ(parallel.nodes()[n].bounds, full.nodes()[n].bounds);
  }
  // One vertex moves: with margin 0 the boxes equal a full refit's again.
  std::vector<Vec3> y = x;
  y[600].z() += 0.5;  // above the whole sheet: its leaf and every node above it grow
  full.refit(y, y, 0.003);
  serial.refit(y, y, 0.003);
  parallel.refit(y, y, 0.003, &tasks);
  EXPECT_GT(serial.lastRefitCounts().refitNodes, 0u);
  EXPECT_LT(serial.lastRefitCounts().refitNodes, 30u);
  EXPECT_EQ(parallel.lastRefitCounts().refitNodes, serial.lastRefitCounts().refitNodes);
  for (std::size_t n = 0; n < full.nodes().size(); ++n) {
    ASSERT_EQ(serial.nodes()[n].bounds, full.nodes()[n].bounds);
    ASSERT_EQ(parallel.nodes()[n].bounds, full.nodes()[n].bounds);
  }
}

}  // namespace
}  // namespace weft
