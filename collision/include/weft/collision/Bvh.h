// Bvh: an AABB tree over the triangles of one mesh, built once, refit every step.
//
// Design note
// -----------
// What. A binary tree of axis-aligned boxes over triangles. Leaves hold up to kMaxLeafTriangles
// triangles. Three queries give broad-phase candidates: the cloth against itself (querySelf),
// two trees against each other (queryPairs: cloth against a triangle-mesh collider) and a tree
// against one box (queryBox).
//
// Why build once and refit. Cloth keeps its topology and moves continuously, so the tree built
// from the rest shape stays good for a long time; refitting (recomputing the boxes bottom-up, no
// change of structure) costs O(n) and allocates nothing, while a rebuild costs O(n log n) and
// allocates. Refit quality degrades only when the cloth is crumpled far from its rest shape,
// and even then the queries stay exact (boxes always bound their triangles); only their speed
// suffers. Rejected: a rebuild every step (allocates, n log n), incremental rotations
// (Kopta et al. 2012: more code, nondeterministic unless done carefully).
//
// Build. Top-down, median split: at every node the triangles are sorted by the centroid
// coordinate along the longest axis of their centroid bounds (ties by triangle index, so the
// order is a total order and the tree is the same on every platform) and cut in two halves.
// Median splits give a balanced tree (depth ⌈log2(n / kMaxLeafTriangles)⌉ + 1), which is what a
// level-by-level parallel refit wants. Rejected: SAH (better trees for ray tracing, but the
// cloth's triangles are all about the same size and the tree is refit, not rebuilt, anyway).
//
// Layout. Nodes are stored level by level (breadth-first); the children of a node are adjacent
// (right = left + 1) and lie on the next level. Refit first computes every triangle's box (swept
// over x_old → x_new, inflated by the thickness), then the levels from the deepest to the root:
// inside a level every node reads only the level below and writes only itself, so each level
// (and the triangle pass) is a TaskSystem::parallelFor over fixed index blocks and gives the
// same bits on any number of threads.
//
// Self query. The classic recursive self-collision: self(n) = self(left) + self(right) +
// pairs(left, right); a pair of triangles is visited exactly once, under their lowest common
// ancestor. The recursion is cut at build time into independent tasks — self(n) for the nodes at
// level kTaskLevel and pairs(left, right) for the internal nodes above it — which the parallel
// query hands to TaskSystem::parallelFor one task per block; each worker appends to its own list,
// and the lists are joined and sorted, so the result does not depend on the thread count. Pairs
// that share a vertex are skipped (they always touch); pairs are reported once, first < second.
//
// Thickness. Every triangle box is inflated by `thickness` on every side, so every pair of
// triangles whose swept volumes come within 2 · thickness of each other is a candidate.
//
// Skipping the refit of what did not move (setRefitMargin). A cloth resting on the floor, or the
// part of it that does, moves by round-off from step to step, yet a full refit rewrites every
// box. With a margin m ≥ 0 the tree keeps two kinds of box: every triangle's own box is still
// recomputed exactly every refit (that pass is needed to know what moved, and it keeps queries
// exact, see below), but a leaf's box is inflated by m when it is refit and kept as long as it
// still contains its triangles' boxes and is no more than 2m larger than them on any side, i.e.
// until its triangles have moved more than m. An internal node is recomputed only when one of
// its children's boxes changed, so a still part of the tree costs one containment test per leaf
// and nothing above it. Queries stay exact: node boxes are only used to prune, and every query
// tests the exact triangle boxes at the leaves, so the pairs it returns (sorted) are bit for bit
// those of a tree refit every step; only the amount of pruning changes (leaves up to 2m larger).
// Deterministic: a node reads its children's flags and writes only its own, level by level.
// A negative margin (the default) refits every node every time.
//
// Ordering and threads. Every query sorts its output (a linear-time radix sort, PairSort.h), so
// results do not depend on traversal order. Queries are const and keep no state in the tree:
// several threads may query one tree at once; refit must not run concurrently with a query.
// refit() and querySelf() take an optional TaskSystem; queryPairs() and queryBox() are serial
// (a collider query is small next to the self query; queryPairs can be cut into tasks the same
// way when a large mesh collider makes it worth it).
//
// Skipping pairs that share a vertex also drops the vertex–triangle and edge–edge tests between
// the other vertices and edges of two triangles around one vertex (a fan folding onto itself);
// a proximity or CCD stage that needs them must add them from the mesh topology.
//
// Cost: a refit is a small fraction of a self query, which is dominated by the candidate pairs of
// non-adjacent neighbours whose inflated boxes touch (bench/results/threading-and-bvh.md).
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <array>
#include <compare>
#include <cstdint>
#include <span>
#include <vector>

namespace weft {

/// Two triangle indices reported by a broad-phase query. Self queries give first < second.
struct TrianglePair {
  Index first = kInvalidIndex;   ///< triangle of the first (or only) mesh
  Index second = kInvalidIndex;  ///< triangle of the second mesh (or the larger index)

  /// Equal when both indices are.
  friend bool operator==(const TrianglePair&, const TrianglePair&) = default;
  /// Lexicographic order (first, then second): the order of every query's output.
  friend auto operator<=>(const TrianglePair&, const TrianglePair&) = default;
};

/// A test a self query applies to every pair (a < b) whose boxes overlap and that shares no
/// vertex: the pairs it refuses are not reported. A plain function and its context, so the
/// traversal is compiled once; it is called from every worker at once, so it must only read.
struct TrianglePairFilter {
  bool (*accepts)(const void* context, Index a, Index b) = nullptr;  ///< null: every pair
  const void* context = nullptr;                                      ///< passed to accepts
};

/// True when triangles `a` and `b` (vertex indices) have a vertex in common. All nine comparisons
/// without branches: the broad phase and the self-collision's feature pairs ask it for every
/// candidate pair, with answers a branch predictor cannot guess.
inline bool trianglesShareVertex(const std::array<Index, 3>& a, const std::array<Index, 3>& b) {
  return ((a[0] == b[0]) | (a[0] == b[1]) | (a[0] == b[2]) | (a[1] == b[0]) | (a[1] == b[1]) |
          (a[1] == b[2]) | (a[2] == b[0]) | (a[2] == b[1]) | (a[2] == b[2])) != 0;
}

/// AABB tree over the triangles of one mesh (see the design note above).
class Bvh {
 public:
  /// Most triangles in one leaf. Larger leaves make the self query faster up to about 16 and
  /// the leaf loops longer; 16 keeps most of the gain (bench/results/threading-and-bvh.md).
  static constexpr Index kMaxLeafTriangles = 16;
  /// Level at which the self query is cut into independent tasks (up to 2^kTaskLevel of them).
  static constexpr Index kTaskLevel = 5;

  /// One node. Leaves: `first` is an offset into triangleOrder() and `count` ≥ 1 triangles.
  /// Internal nodes: `first` is the left child (the right child is first + 1), `count` is 0.
  struct Node {
    Aabb bounds;          ///< m, union of the (swept, inflated) boxes of its triangles
    Index first = 0;      ///< leaf: first slot in triangleOrder(); internal: left child
    Index count = 0;      ///< leaf: number of triangles; internal: 0
    /// True for a leaf.
    bool isLeaf() const { return count != 0; }
  };

  /// An empty tree (no triangles); every query returns nothing.
  Bvh() = default;

  /// Builds the tree over `triangleIndices` (three per triangle) from the centroids at
  /// `positions` (usually the rest shape), then refits it to `positions` with zero thickness.
  /// Leaves hold at most `maxLeafTriangles` (1 to kMaxLeafTriangles; point queries prune best
  /// with small leaves, the self query runs fastest with large ones). Errors: index count not a
  /// multiple of three, index out of range, non-finite position, leaf size out of range.
  static Result<Bvh> build(std::span<const Index> triangleIndices,
                           std::span<const Vec3> positions,
                           Index maxLeafTriangles = kMaxLeafTriangles);

  /// Recomputes every box for static triangles at `positions`, inflated by `thickness` (m).
  /// `positions` must hold vertexCount() entries. Allocates nothing. With `tasks`, the loops run
  /// through its parallelFor (same bits as serial).
  void refit(std::span<const Vec3> positions, Real thickness, TaskSystem* tasks = nullptr);
  /// Recomputes every box to bound each triangle swept linearly from `oldPositions` to
  /// `newPositions` (the box of both end states), inflated by `thickness` (m). Allocates nothing.
  /// With `tasks`, the loops run through its parallelFor (same bits as serial).
  void refit(std::span<const Vec3> oldPositions, std::span<const Vec3> newPositions,
             Real thickness, TaskSystem* tasks = nullptr);

  /// m: how far a leaf's triangles may move before its box is refit (see the design note):
  /// negative (the default) refits every node on every refit; 0 skips only nodes whose boxes
  /// come out bit for bit unchanged; m > 0 inflates leaf boxes by m and skips leaves whose
  /// triangles moved less than m, and every internal node above only skipped children. Raising it
  /// skips more refits and prunes the queries less (their results never change).
  void setRefitMargin(Real margin) { m_refitMargin = margin; }
  /// m, the refit margin (setRefitMargin()).
  Real refitMargin() const { return m_refitMargin; }
  /// Nodes the last refit recomputed and nodes it kept (sum: nodes().size()).
  struct RefitCounts {
    Index refitNodes = 0;    ///< nodes whose box was recomputed
    Index skippedNodes = 0;  ///< nodes whose box was kept
  };
  /// What the last refit() recomputed and kept.
  const RefitCounts& lastRefitCounts() const { return m_lastRefit; }

  /// Clears `pairs`, then writes every pair (i < j) of triangles whose boxes overlap, that
  /// share no vertex and that `filter` accepts, sorted.
  void querySelf(std::vector<TrianglePair>& pairs, const TrianglePairFilter& filter = {}) const;
  /// querySelf() with its tasks spread over `tasks`; `workerPairs` (built from the same
  /// TaskSystem, reused from call to call) collects each worker's pairs. Same result as serial.
  void querySelf(std::vector<TrianglePair>& pairs, TaskSystem& tasks,
                 PerWorker<std::vector<TrianglePair>>& workerPairs,
                 const TrianglePairFilter& filter = {}) const;
  /// Clears `pairs`, then writes every pair (triangle of this tree, triangle of `other`) whose
  /// boxes overlap, sorted. Both trees must be refit in the same frame of reference.
  void queryPairs(const Bvh& other, std::vector<TrianglePair>& pairs) const;
  /// Clears `triangles`, then writes every triangle whose box overlaps `box`, sorted.
  void queryBox(const Aabb& box, std::vector<Index>& triangles) const;

  /// Number of triangles.
  Index triangleCount() const { return static_cast<Index>(m_triangles.size()); }
  /// Number of vertices the positions passed to refit() must hold.
  Index vertexCount() const { return m_vertexCount; }
  /// The three vertex indices of triangle `triangle`.
  const std::array<Index, 3>& triangle(Index triangle) const { return m_triangles[triangle]; }
  /// Box of the whole mesh (empty when there are no triangles).
  Aabb bounds() const { return m_nodes.empty() ? Aabb::empty() : m_nodes.front().bounds; }
  /// All nodes, level by level; node 0 is the root.
  const std::vector<Node>& nodes() const { return m_nodes; }
  /// Index of the first node of every level, plus one past the last node (levelCount() + 1).
  const std::vector<Index>& levelBegins() const { return m_levelBegins; }
  /// Number of levels (0 for an empty tree).
  Index levelCount() const { return m_levelBegins.empty() ? 0 : Index(m_levelBegins.size() - 1); }
  /// Triangle indices in leaf order: leaf n holds slots [n.first, n.first + n.count).
  const std::vector<Index>& triangleOrder() const { return m_triangleOrder; }
  /// Box of the triangle in leaf slot `slot` as of the last refit.
  const Aabb& slotBounds(Index slot) const { return m_slotBounds[slot]; }
  /// The triangles of a leaf, as indices into the mesh.
  std::span<const Index> leafTriangles(const Node& leaf) const {
    return std::span<const Index>(m_triangleOrder).subspan(leaf.first, leaf.count);
  }

 private:
  struct NodePair {
    Index first;
    Index second;
  };

  void refitTriangles(std::span<const Vec3> oldPositions, std::span<const Vec3> newPositions,
                      Real thickness, TaskSystem* tasks);
  void refitNodes(TaskSystem* tasks);
  void runSelfTask(const NodePair& task, const TrianglePairFilter& filter,
                   std::vector<TrianglePair>& pairs) const;
  bool slotsShareVertex(Index slotA, Index slotB) const;
  void addSlotPair(Index slotA, Index slotB, const TrianglePairFilter& filter,
                   std::vector<TrianglePair>& pairs) const;
  void selfNode(Index node, const TrianglePairFilter& filter,
                std::vector<TrianglePair>& pairs) const;
  void selfPair(Index a, Index b, const TrianglePairFilter& filter,
                std::vector<TrianglePair>& pairs) const;

  std::vector<std::array<Index, 3>> m_triangles;  // by triangle index
  std::vector<Index> m_triangleOrder;             // leaf slot -> triangle index
  std::vector<std::array<Index, 3>> m_slotTriangles;  // leaf slot -> its vertices (no indirection)
  std::vector<Aabb> m_slotBounds;                 // leaf slot -> box of that triangle
  std::vector<Node> m_nodes;                      // level order
  std::vector<Index> m_levelBegins;               // first node of each level, then m_nodes.size()
  std::vector<NodePair> m_selfTasks;              // first == second: self(first); else a pair
  // Per node, last refit: bit 0 = recomputed, bit 1 = box changed (read by the parent).
  std::vector<std::uint8_t> m_nodeRefitFlags;
  Real m_refitMargin = -1;                        // negative: refit everything (setRefitMargin)
  RefitCounts m_lastRefit;
  Index m_vertexCount = 0;
};

}  // namespace weft
