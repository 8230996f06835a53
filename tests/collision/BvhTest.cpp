// Bvh: build validation, refit bounds against brute force, and every query against an O(n²)
// reference on crumpled and folded grids.
#include <weft/collision/Bvh.h>

#include "collision/CollisionTestSupport.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

using ::testing::HasSubstr;
using test::MeshArrays;

Bvh buildTree(const MeshArrays& mesh) {
  Result<Bvh> tree = Bvh::build(mesh.indices, mesh.positions);
  EXPECT_TRUE(tree.ok()) << tree.error().message;
  return std::move(tree).value();
}

// Box of every node computed from scratch: the union of its leaves' triangle boxes.
Aabb bruteForceNodeBox(const Bvh& tree, Index n, const MeshArrays& mesh,
                       const std::vector<Vec3>& oldX, const std::vector<Vec3>& newX,
                       Real thickness) {
  const Bvh::Node& node = tree.nodes()[n];
  if (node.isLeaf()) {
    Aabb box;
    for (Index t : tree.leafTriangles(node)) {
      box.expand(test::sweptTriangleBox(mesh, t, oldX, newX, thickness));
    }
    return box;
  }
  Aabb box = bruteForceNodeBox(tree, node.first, mesh, oldX, newX, thickness);
  box.expand(bruteForceNodeBox(tree, node.first + 1, mesh, oldX, newX, thickness));
  return box;
}

std::vector<TrianglePair> bruteForceSelf(const MeshArrays& mesh, const std::vector<Vec3>& oldX,
                                         const std::vector<Vec3>& newX, Real thickness) {
  std::vector<TrianglePair> pairs;
  for (Index i = 0; i < mesh.triangleCount(); ++i) {
    const Aabb boxI = test::sweptTriangleBox(mesh, i, oldX, newX, thickness);
    for (Index j = i + 1; j < mesh.triangleCount(); ++j) {
      if (test::shareVertex(mesh.triangle(i), mesh.triangle(j))) continue;
      if (boxI.overlaps(test::sweptTriangleBox(mesh, j, oldX, newX, thickness))) {
        pairs.push_back({i, j});
      }
    }
  }
  return pairs;
}

TEST(Bvh, BuildRejectsBadInput) {
  const std::vector<Vec3> positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const std::vector<Index> notMultipleOfThree = {0, 1};
  Result<Bvh> tree = Bvh::build(notMultipleOfThree, positions);
  ASSERT_FALSE(tree.ok());
  EXPECT_THAT(tree.error().message, HasSubstr("not a multiple of three"));

  const std::vector<Index> outOfRange = {0, 1, 3};
  tree = Bvh::build(outOfRange, positions);
  ASSERT_FALSE(tree.ok());
  EXPECT_THAT(tree.error().message, HasSubstr("index 2 (triangle 0) is 3"));

  std::vector<Vec3> nonFinite = positions;
  nonFinite[1].y() = std::numeric_limits<Real>::quiet_NaN();
  const std::vector<Index> one = {0, 1, 2};
  tree = Bvh::build(one, nonFinite);
  ASSERT_FALSE(tree.ok());
  EXPECT_THAT(tree.error().message, HasSubstr("position 1 is not finite"));
}

TEST(Bvh, EmptyMeshAnswersNothing) {
  const std::vector<Vec3> positions = {Vec3(0, 0, 0)};
  Result<Bvh> tree = Bvh::build({}, positions);
  ASSERT_TRUE(tree.ok());
  tree->refit(positions, 0.1);
  std::vector<TrianglePair> pairs{{1, 2}};
  tree->querySelf(pairs);
  EXPECT_TRUE(pairs.empty());
  std::vector<Index> triangles{7};
  tree->queryBox(Aabb::fromCorners(Vec3::Constant(-1), Vec3::Constant(1)), triangles);
  EXPECT_TRUE(triangles.empty());
  EXPECT_TRUE(tree->bounds().isEmpty());
}

TEST(Bvh, StructureIsLevelOrderedBalancedAndCoversEveryTriangleOnce) {
  const MeshArrays mesh = test::makeGrid(21, 21, 0.05);
  const Bvh tree = buildTree(mesh);
  const auto& nodes = tree.nodes();
  std::vector<int> seen(mesh.triangleCount(), 0);
  for (Index level = 0; level < tree.levelCount(); ++level) {
    for (Index n = tree.levelBegins()[level]; n < tree.levelBegins()[level + 1]; ++n) {
      if (nodes[n].isLeaf()) {
        EXPECT_LE(nodes[n].count, Bvh::kMaxLeafTriangles);
        for (Index t : tree.leafTriangles(nodes[n])) ++seen[t];
      } else {
        // Children on the next level, adjacent.
        EXPECT_GE(nodes[n].first, tree.levelBegins()[level + 1]);
        EXPECT_LT(nodes[n].first + 1, tree.levelBegins()[level + 2]);
      }
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int count) { return count == 1; }));
  // Median splits: a balanced tree of ⌈log2(800 / kMaxLeafTriangles)⌉ + 1 levels.
  const Real leavesNeeded = 800.0 / Bvh::kMaxLeafTriangles;
  EXPECT_EQ(tree.levelCount(), Index(std::ceil(std::log2(leavesNeeded))) + 1);
}

TEST(Bvh, BuildIsDeterministic) {
  const MeshArrays mesh = test::makeGrid(17, 13, 0.1);
  const Bvh first = buildTree(mesh);
  const Bvh second = buildTree(mesh);
  ASSERT_EQ(first.nodes().size(), second.nodes().size());
  EXPECT_EQ(first.triangleOrder(), second.triangleOrder());
  for (std::size_t n = 0; n < first.nodes().size(); ++n) {
    EXPECT_EQ(first.nodes()[n].bounds, second.nodes()[n].bounds);
    EXPECT_EQ(first.nodes()[n].first, second.nodes()[n].first);
    EXPECT_EQ(first.nodes()[n].count, second.nodes()[n].count);
  }
}

TEST(Bvh, RefitMatchesBoundsComputedFromScratchAfterRandomDeformations) {
  const MeshArrays mesh = test::makeGrid(20, 20, 0.05);
  Bvh tree = buildTree(mesh);
  std::vector<Vec3> previous = mesh.positions;
  const Real thickness = 0.003;
  for (unsigned step = 0; step < 5; ++step) {
    const std::vector<Vec3> current = test::crumple(mesh.positions, 0.05 * (step + 1), step);
    tree.refit(previous, current, thickness);
    for (Index n = 0; n < tree.nodes().size(); ++n) {
      ASSERT_EQ(tree.nodes()[n].bounds,
                bruteForceNodeBox(tree, n, mesh, previous, current, thickness))
          << "node " << n << " after step " << step;
    }
    // A fresh tree refit once to the same motion has the same boxes: refit keeps no state.
    Bvh fresh = buildTree(mesh);
    fresh.refit(previous, current, thickness);
    for (Index n = 0; n < tree.nodes().size(); ++n) {
      ASSERT_EQ(tree.nodes()[n].bounds, fresh.nodes()[n].bounds);
    }
    // The root bounds every swept vertex.
    for (std::size_t v = 0; v < current.size(); ++v) {
      EXPECT_TRUE(tree.bounds().contains(previous[v]));
      EXPECT_TRUE(tree.bounds().contains(current[v]));
    }
    previous = current;
  }
}

TEST(Bvh, SelfQueryEqualsBruteForceOnCrumpledGrids) {
  const MeshArrays mesh = test::makeGrid(20, 20, 0.05);
  Bvh tree = buildTree(mesh);
  std::vector<TrianglePair> pairs;
  for (unsigned seed = 0; seed < 4; ++seed) {
    const std::vector<Vec3> oldX = test::crumple(mesh.positions, 0.03, 100 + seed);
    const std::vector<Vec3> newX = test::crumple(mesh.positions, 0.03, 200 + seed);
    const Real thickness = 0.002 * seed;
    tree.refit(oldX, newX, thickness);
    tree.querySelf(pairs);
    const std::vector<TrianglePair> expected = bruteForceSelf(mesh, oldX, newX, thickness);
    EXPECT_GT(expected.size(), 100u) << "the test should exercise many overlaps";
    EXPECT_EQ(pairs, expected) << "seed " << seed;
  }
}

TEST(Bvh, SelfQueryEqualsBruteForceOnFoldedGrid) {
  // Folds bring far-apart triangles (different subtrees) together.
  const MeshArrays mesh = test::makeGrid(24, 16, 0.05);
  Bvh tree = buildTree(mesh);
  const std::vector<Vec3> folded = test::fold(mesh.positions, 0.1, 0.4, 0.01, 7);
  tree.refit(mesh.positions, folded, 0.003);
  std::vector<TrianglePair> pairs;
  tree.querySelf(pairs);
  EXPECT_EQ(pairs, bruteForceSelf(mesh, mesh.positions, folded, 0.003));
  // Flat and at rest: only neighbours that share no vertex but whose boxes touch.
  tree.refit(mesh.positions, 0.0);
  tree.querySelf(pairs);
  EXPECT_EQ(pairs, bruteForceSelf(mesh, mesh.positions, mesh.positions, 0.0));
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  for (const TrianglePair& pair : pairs) EXPECT_LT(pair.first, pair.second);
}

TEST(Bvh, PairQueryEqualsBruteForce) {
  const MeshArrays cloth = test::makeGrid(20, 20, 0.05);
  MeshArrays collider = test::makeGrid(9, 7, 0.08);
  for (Vec3& x : collider.positions) x = Vec3(x.x() + 0.2, 0.3, x.y() - 0.2);  // crosses the cloth
  Bvh clothTree = buildTree(cloth);
  Bvh colliderTree = buildTree(collider);
  for (unsigned seed = 0; seed < 3; ++seed) {
    const std::vector<Vec3> oldX = test::crumple(cloth.positions, 0.05, 300 + seed);
    const std::vector<Vec3> newX = test::crumple(cloth.positions, 0.05, 400 + seed);
    const std::vector<Vec3> colliderNow = test::crumple(collider.positions, 0.02, 500 + seed);
    clothTree.refit(oldX, newX, 0.003);
    colliderTree.refit(colliderNow, 0.0);
    std::vector<TrianglePair> pairs;
    clothTree.queryPairs(colliderTree, pairs);

    std::vector<TrianglePair> expected;
    for (Index i = 0; i < cloth.triangleCount(); ++i) {
      const Aabb box = test::sweptTriangleBox(cloth, i, oldX, newX, 0.003);
      for (Index j = 0; j < collider.triangleCount(); ++j) {
        if (box.overlaps(test::sweptTriangleBox(collider, j, colliderNow, colliderNow, 0.0))) {
          expected.push_back({i, j});
        }
      }
    }
    EXPECT_GT(expected.size(), 10u);
    EXPECT_EQ(pairs, expected) << "seed " << seed;
  }
}

TEST(Bvh, BoxQueryEqualsBruteForce) {
  const MeshArrays mesh = test::makeGrid(20, 20, 0.05);
  Bvh tree = buildTree(mesh);
  const std::vector<Vec3> x = test::crumple(mesh.positions, 0.04, 11);
  tree.refit(x, 0.001);
  std::mt19937 random(5);
  std::uniform_real_distribution<Real> coordinate(-0.1, 1.0);
  std::uniform_real_distribution<Real> size(0.0, 0.3);
  std::vector<Index> triangles;
  int nonEmpty = 0;
  for (int query = 0; query < 50; ++query) {
    const Vec3 low(coordinate(random), coordinate(random), -0.05);
    const Aabb box = Aabb::fromCorners(low, low + Vec3(size(random), size(random), 0.1));
    tree.queryBox(box, triangles);
    std::vector<Index> expected;
    for (Index t = 0; t < mesh.triangleCount(); ++t) {
      if (test::sweptTriangleBox(mesh, t, x, x, 0.001).overlaps(box)) expected.push_back(t);
    }
    nonEmpty += !expected.empty();
    EXPECT_EQ(triangles, expected) << "query " << query;
  }
  EXPECT_GT(nonEmpty, 25);
}

// The curtain's size, folded over a step: 2,400 triangles, so the triangle pass and the deep
// levels split into several blocks, and over a thousand overlapping pairs.
struct FoldedCurtain {
  MeshArrays mesh = test::makeGrid(41, 31, 0.05);
  std::vector<Vec3> oldX = test::fold(mesh.positions, 0.1, 0.5, 0.01, 1);
  std::vector<Vec3> newX = test::fold(mesh.positions, 0.12, 0.5, 0.01, 2);
  static constexpr Real kThickness = 0.003;  // m

  // A tree over the mesh, refit to the step.
  Bvh refitTree() const {
    Bvh tree = buildTree(mesh);
    tree.refit(oldX, newX, kThickness);
    return tree;
  }
  // The unfiltered serial self query of `tree`.
  static std::vector<TrianglePair> plainPairs(const Bvh& tree) {
    std::vector<TrianglePair> pairs;
    tree.querySelf(pairs);
    EXPECT_GT(pairs.size(), 1000u) << "the test should exercise many overlaps";
    return pairs;
  }
};

TEST(Bvh, ParallelRefitAndSelfQueryGiveTheSerialResult) {
  const FoldedCurtain curtain;
  const Bvh serial = curtain.refitTree();
  const std::vector<TrianglePair> expected = FoldedCurtain::plainPairs(serial);
  for (int threads : {1, 2, 3}) {
    TaskSystem tasks(TaskSystemSettings{threads});
    PerWorker<std::vector<TrianglePair>> workerPairs(tasks);
    Bvh parallel = buildTree(curtain.mesh);
    std::vector<TrianglePair> pairs;
    for (int repeat = 0; repeat < 3; ++repeat) {
      parallel.refit(curtain.oldX, curtain.newX, FoldedCurtain::kThickness, &tasks);
      for (std::size_t n = 0; n < serial.nodes().size(); ++n) {
        ASSERT_EQ(parallel.nodes()[n].bounds, serial.nodes()[n].bounds) << threads << " threads";
      }
      parallel.querySelf(pairs, tasks, workerPairs);
      EXPECT_EQ(pairs, expected) << threads << " threads, repeat " << repeat;
    }
  }
}

TEST(Bvh, AFilteredSelfQueryReportsExactlyThePairsTheFilterAccepts) {
  // The filter sees every pair the plain query reports, as (smaller, larger), and only those;
  // the result is the plain one without the refused pairs, in the same order, serial or parallel.
  const Bvh tree = FoldedCurtain().refitTree();
  const std::vector<TrianglePair> all = FoldedCurtain::plainPairs(tree);
  struct Context {
    std::vector<TrianglePair> asked;
    bool misordered = false;
  } context;
  // Refuses pairs whose index sum is divisible by 3: a rule unrelated to the geometry.
  const auto refuse = [](Index a, Index b) { return (a + b) % 3 == 0; };
  const TrianglePairFilter recording{
      [](const void* opaque, Index a, Index b) {
        auto& c = *static_cast<Context*>(const_cast<void*>(opaque));
        c.asked.push_back({a, b});
        c.misordered = c.misordered || !(a < b);
        return (a + b) % 3 != 0;
      },
      &context};
  std::vector<TrianglePair> filtered;
  tree.querySelf(filtered, recording);
  std::sort(context.asked.begin(), context.asked.end());
  EXPECT_EQ(context.asked, all) << "the filter is asked about exactly the plain query's pairs";
  EXPECT_FALSE(context.misordered);
  std::vector<TrianglePair> expected;
  for (const TrianglePair& pair : all) {
    if (!refuse(pair.first, pair.second)) expected.push_back(pair);
  }
  ASSERT_LT(expected.size(), all.size());
  EXPECT_EQ(filtered, expected);

  const TrianglePairFilter pure{
      [](const void*, Index a, Index b) { return (a + b) % 3 != 0; }, nullptr};
  for (int threads : {1, 2, 3}) {
    TaskSystem tasks(TaskSystemSettings{threads});
    PerWorker<std::vector<TrianglePair>> workerPairs(tasks);
    std::vector<TrianglePair> pairs;
    tree.querySelf(pairs, tasks, workerPairs, pure);
    EXPECT_EQ(pairs, expected) << threads << " threads";
  }
}

}  // namespace
}  // namespace weft
