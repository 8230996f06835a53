// Bvh: build (median split, level-order layout), refit (bottom-up by level) and the three
// broad-phase queries. See Bvh.h for the design note.
#include <weft/collision/Bvh.h>

#include "BlockLoop.h"
#include "PairSort.h"

#include <algorithm>
#include <cassert>
#include <sstream>

namespace weft {
namespace {

// Triangles per block of the refit's triangle pass and nodes per block of a level. The whole
// refit of 38,400 triangles takes ~0.25 ms (≈ 6 ns per triangle box), so 1,024 per block is
// ~6 µs: above the 2.5–5 µs per block that GrainSizes.h asks for. Levels smaller than a block
// (the top ten of a ×16 curtain) run inline without a fork.
constexpr Index kRefitGrain = 1024;

// A node of the recursive build before it is renumbered in level order.
struct BuildNode {
  Index begin = 0;  // slot range [begin, end) in the triangle order
  Index end = 0;
  Index left = kInvalidIndex;
  Index right = kInvalidIndex;
};

Index buildRecursive(std::vector<BuildNode>& nodes, std::vector<Index>& order,
                     const std::vector<Vec3>& centroids, Index begin, Index end,
                     Index maxLeafTriangles) {
  const Index self = static_cast<Index>(nodes.size());
  nodes.push_back({begin, end, kInvalidIndex, kInvalidIndex});
  if (end - begin <= maxLeafTriangles) return self;

  Aabb centroidBounds;
  for (Index slot = begin; slot < end; ++slot) centroidBounds.expand(centroids[order[slot]]);
  const Vec3 extent = centroidBounds.extent();
  int axis = 0;  // longest axis; ties go to the lowest axis
  if (extent[1] > extent[axis]) axis = 1;
  if (extent[2] > extent[axis]) axis = 2;

  // A total order (coordinate, then triangle index): the split is the same on every platform.
  std::sort(order.begin() + begin, order.begin() + end, [&](Index a, Index b) {
    const Real ca = centroids[a][axis];
    const Real cb = centroids[b][axis];
    return ca < cb || (ca == cb && a < b);
  });
  const Index middle = begin + (end - begin) / 2;
  const Index left = buildRecursive(nodes, order, centroids, begin, middle, maxLeafTriangles);
  const Index right = buildRecursive(nodes, order, centroids, middle, end, maxLeafTriangles);
  nodes[self].left = left;
  nodes[self].right = right;
  return self;
}

std::string describeIndex(std::size_t position, Index value, std::size_t vertexCount) {
  std::ostringstream text;
  text << "Bvh: index " << position << " (triangle " << position / 3 << ") is " << value
       << " but there are only " << vertexCount << " positions; every index must be below the "
       << "vertex count";
  return text.str();
}

}  // namespace

Result<Bvh> Bvh::build(std::span<const Index> triangleIndices, std::span<const Vec3> positions,
                       Index maxLeafTriangles) {
  if (maxLeafTriangles < 1 || maxLeafTriangles > kMaxLeafTriangles) {
    std::ostringstream text;
    text << "Bvh: " << maxLeafTriangles << " triangles per leaf is out of range; pass 1 to "
         << kMaxLeafTriangles;
    return Error{text.str()};
  }
  if (triangleIndices.size() % 3 != 0) {
    std::ostringstream text;
    text << "Bvh: " << triangleIndices.size()
         << " triangle indices is not a multiple of three; pass three vertex indices per triangle";
    return Error{text.str()};
  }
  for (std::size_t i = 0; i < triangleIndices.size(); ++i) {
    if (triangleIndices[i] >= positions.size()) {
      return Error{describeIndex(i, triangleIndices[i], positions.size())};
    }
  }
  for (std::size_t v = 0; v < positions.size(); ++v) {
    if (!isFinite(positions[v])) {
      std::ostringstream text;
      text << "Bvh: position " << v << " is not finite; pass finite positions in metres";
      return Error{text.str()};
    }
  }

  Bvh tree;
  tree.m_vertexCount = static_cast<Index>(positions.size());
  const Index triangleCount = static_cast<Index>(triangleIndices.size() / 3);
  tree.m_triangles.resize(triangleCount);
  std::vector<Vec3> centroids(triangleCount);
  for (Index t = 0; t < triangleCount; ++t) {
    tree.m_triangles[t] = {triangleIndices[3 * t], triangleIndices[3 * t + 1],
                           triangleIndices[3 * t + 2]};
    centroids[t] = (positions[triangleIndices[3 * t]] + positions[triangleIndices[3 * t + 1]] +
                    positions[triangleIndices[3 * t + 2]]) / 3.0;
  }
  if (triangleCount == 0) return tree;

  tree.m_triangleOrder.resize(triangleCount);
  for (Index t = 0; t < triangleCount; ++t) tree.m_triangleOrder[t] = t;
  std::vector<BuildNode> buildNodes;
  buildNodes.reserve(2 * triangleCount);
  buildRecursive(buildNodes, tree.m_triangleOrder, centroids, 0, triangleCount, maxLeafTriangles);

  // Renumber breadth-first: the children of the nodes of one level are appended, in order, to
  // the next level, so siblings are adjacent and every level is one contiguous range.
  tree.m_nodes.reserve(buildNodes.size());
  std::vector<Index> level{0};
  std::vector<Index> nextLevel;
  while (!level.empty()) {
    const Index levelBegin = static_cast<Index>(tree.m_nodes.size());
    tree.m_levelBegins.push_back(levelBegin);
    const Index nextLevelBegin = levelBegin + static_cast<Index>(level.size());
    nextLevel.clear();
    for (Index b : level) {
      const BuildNode& built = buildNodes[b];
      Node node;
      if (built.left == kInvalidIndex) {
        node.first = built.begin;
        node.count = built.end - built.begin;
      } else {
        node.first = nextLevelBegin + static_cast<Index>(nextLevel.size());
        node.count = 0;
        nextLevel.push_back(built.left);
        nextLevel.push_back(built.right);
      }
      tree.m_nodes.push_back(node);
    }
    std::swap(level, nextLevel);
  }
  tree.m_levelBegins.push_back(static_cast<Index>(tree.m_nodes.size()));

  // Self-query tasks: pairs(left, right) for internal nodes above kTaskLevel, self(leaf) for
  // leaves above it, self(node) for every node on it. Together they cover every triangle pair
  // exactly once (under its lowest common ancestor).
  for (Index levelIndex = 0; levelIndex < tree.levelCount() && levelIndex <= kTaskLevel;
       ++levelIndex) {
    for (Index n = tree.m_levelBegins[levelIndex]; n < tree.m_levelBegins[levelIndex + 1]; ++n) {
      const Node& node = tree.m_nodes[n];
      if (node.isLeaf() || levelIndex == kTaskLevel) {
        tree.m_selfTasks.push_back({n, n});
      } else {
        tree.m_selfTasks.push_back({node.first, node.first + 1});
      }
    }
  }

  tree.m_slotTriangles.resize(triangleCount);
  for (Index slot = 0; slot < triangleCount; ++slot) {
    tree.m_slotTriangles[slot] = tree.m_triangles[tree.m_triangleOrder[slot]];
  }
  tree.m_slotBounds.resize(triangleCount);
  tree.refit(positions, 0.0);
  return tree;
}

void Bvh::refit(std::span<const Vec3> positions, Real thickness, TaskSystem* tasks) {
  refit(positions, positions, thickness, tasks);
}

void Bvh::refit(std::span<const Vec3> oldPositions, std::span<const Vec3> newPositions,
                Real thickness, TaskSystem* tasks) {
  assert(oldPositions.size() == m_vertexCount && newPositions.size() == m_vertexCount &&
         "Bvh::refit: pass one position per vertex of the mesh the tree was built for");
  refitTriangles(oldPositions, newPositions, thickness, tasks);
  refitNodes(tasks);
}

void Bvh::refitTriangles(std::span<const Vec3> oldPositions, std::span<const Vec3> newPositions,
                         Real thickness, TaskSystem* tasks) {
  detail::forEachBlock(tasks, triangleCount(), kRefitGrain, [&](Index begin, Index end, int) {
    for (Index slot = begin; slot < end; ++slot) {
      const std::array<Index, 3>& corners = m_slotTriangles[slot];
      Aabb box = Aabb::fromCorners(oldPositions[corners[0]], newPositions[corners[0]]);
      box.expand(oldPositions[corners[1]]);
      box.expand(newPositions[corners[1]]);
      box.expand(oldPositions[corners[2]]);
      box.expand(newPositions[corners[2]]);
      box.inflate(thickness);
      m_slotBounds[slot] = box;
    }
  });
}

void Bvh::refitNodes(TaskSystem* tasks) {
  constexpr std::uint8_t kRecomputed = 1, kChanged = 2;
  // Sized with the tree: build() refits once, so this allocates at build time only.
  if (m_nodeRefitFlags.size() != m_nodes.size()) m_nodeRefitFlags.assign(m_nodes.size(), 0);
  const bool refitAll = !(m_refitMargin >= 0);  // negative or NaN: the full refit
  const Real margin = refitAll ? Real(0) : m_refitMargin;
  // Deepest level first: a node reads only its children (next level) or its slots.
  for (Index levelIndex = levelCount(); levelIndex-- > 0;) {
    const Index levelBegin = m_levelBegins[levelIndex];
    const Index levelSize = m_levelBegins[levelIndex + 1] - levelBegin;
    detail::forEachBlock(tasks, levelSize, kRefitGrain, [&](Index begin, Index end, int) {
      for (Index n = levelBegin + begin; n < levelBegin + end; ++n) {
        Node& node = m_nodes[n];
        std::uint8_t flags = 0;
        if (node.isLeaf()) {
          Aabb box = m_slotBounds[node.first];
          for (Index slot = node.first + 1; slot < node.first + node.count; ++slot) {
            box.expand(m_slotBounds[slot]);
          }
          if (refitAll) {
            node.bounds = box;
            flags = kRecomputed | kChanged;
          } else {
            // Keep the box while it holds the triangles and is at most 2m too large on any side.
            Aabb loosest = box;
            loosest.inflate(2 * margin);
            const bool holds = (node.bounds.min.array() <= box.min.array()).all() &&
                               (node.bounds.max.array() >= box.max.array()).all();
            const bool tightEnough = (loosest.min.array() <= node.bounds.min.array()).all() &&
                                     (loosest.max.array() >= node.bounds.max.array()).all();
            if (!holds || !tightEnough) {
              box.inflate(margin);
              flags = kRecomputed | (box == node.bounds ? 0 : kChanged);
              node.bounds = box;
            }
          }
        } else if (refitAll || (m_nodeRefitFlags[node.first] & kChanged) ||
                   (m_nodeRefitFlags[node.first + 1] & kChanged)) {
          Aabb box = m_nodes[node.first].bounds;
          box.expand(m_nodes[node.first + 1].bounds);
          flags = kRecomputed | (refitAll || !(box == node.bounds) ? kChanged : 0);
          node.bounds = box;
        }
        m_nodeRefitFlags[n] = flags;
      }
    });
  }
  // Counted serially after the levels: an integer count has one value whatever the order.
  Index recomputed = 0;
  for (std::uint8_t flags : m_nodeRefitFlags) recomputed += flags & kRecomputed;
  m_lastRefit.refitNodes = recomputed;
  m_lastRefit.skippedNodes = Index(m_nodes.size()) - recomputed;
}

inline bool Bvh::slotsShareVertex(Index slotA, Index slotB) const {
  return trianglesShareVertex(m_slotTriangles[slotA], m_slotTriangles[slotB]);
}

inline void Bvh::addSlotPair(Index slotA, Index slotB, const TrianglePairFilter& filter,
                              std::vector<TrianglePair>& pairs) const {
  if (!m_slotBounds[slotA].overlaps(m_slotBounds[slotB]) || slotsShareVertex(slotA, slotB)) return;
  const Index a = m_triangleOrder[slotA];
  const Index b = m_triangleOrder[slotB];
  const TrianglePair pair = a < b ? TrianglePair{a, b} : TrianglePair{b, a};
  if (filter.accepts && !filter.accepts(filter.context, pair.first, pair.second)) return;
  pairs.push_back(pair);
}

void Bvh::selfNode(Index n, const TrianglePairFilter& filter,
                   std::vector<TrianglePair>& pairs) const {
  const Node& node = m_nodes[n];
  if (!node.isLeaf()) {
    selfNode(node.first, filter, pairs);
    selfNode(node.first + 1, filter, pairs);
    if (m_nodes[node.first].bounds.overlaps(m_nodes[node.first + 1].bounds)) {
      selfPair(node.first, node.first + 1, filter, pairs);
    }
    return;
  }
  const Index end = node.first + node.count;
  for (Index i = node.first; i < end; ++i) {
    for (Index j = i + 1; j < end; ++j) addSlotPair(i, j, filter, pairs);
  }
}

// Precondition: the boxes of nodes a and b overlap (checked by the caller, which saves a call
// for every pair that does not).
void Bvh::selfPair(Index a, Index b, const TrianglePairFilter& filter,
                   std::vector<TrianglePair>& pairs) const {
  const Node& nodeA = m_nodes[a];
  const Node& nodeB = m_nodes[b];
  if (nodeA.isLeaf() && nodeB.isLeaf()) {
    // Only triangles that reach into the common part of the two leaf boxes can pair up: filter
    // both sides against it first (a few per cent faster on the ×16 curtain).
    const Aabb common{nodeA.bounds.min.cwiseMax(nodeB.bounds.min),
                      nodeA.bounds.max.cwiseMin(nodeB.bounds.max)};
    Index slotsB[kMaxLeafTriangles];
    Index countB = 0;
    for (Index j = nodeB.first; j < nodeB.first + nodeB.count; ++j) {
      if (m_slotBounds[j].overlaps(common)) slotsB[countB++] = j;
    }
    for (Index i = nodeA.first; countB > 0 && i < nodeA.first + nodeA.count; ++i) {
      if (!m_slotBounds[i].overlaps(common)) continue;
      for (Index k = 0; k < countB; ++k) addSlotPair(i, slotsB[k], filter, pairs);
    }
    return;
  }
  // Descend the bigger node (a leaf never): keeps the two boxes of similar size.
  const bool descendA =
      nodeB.isLeaf() || (!nodeA.isLeaf() && nodeA.bounds.halfSurfaceArea() >=
                                                nodeB.bounds.halfSurfaceArea());
  const Index parent = descendA ? a : b;
  const Index other = descendA ? b : a;
  const Aabb& otherBounds = m_nodes[other].bounds;
  for (Index child = m_nodes[parent].first; child < m_nodes[parent].first + 2; ++child) {
    if (m_nodes[child].bounds.overlaps(otherBounds)) selfPair(child, other, filter, pairs);
  }
}

void Bvh::runSelfTask(const NodePair& task, const TrianglePairFilter& filter,
                      std::vector<TrianglePair>& pairs) const {
  if (task.first == task.second) {
    selfNode(task.first, filter, pairs);
  } else if (m_nodes[task.first].bounds.overlaps(m_nodes[task.second].bounds)) {
    selfPair(task.first, task.second, filter, pairs);
  }
}

void Bvh::querySelf(std::vector<TrianglePair>& pairs, const TrianglePairFilter& filter) const {
  pairs.clear();
  for (const NodePair& task : m_selfTasks) runSelfTask(task, filter, pairs);
  detail::sortTrianglePairs(pairs, triangleCount());
}

void Bvh::querySelf(std::vector<TrianglePair>& pairs, TaskSystem& tasks,
                    PerWorker<std::vector<TrianglePair>>& workerPairs,
                    const TrianglePairFilter& filter) const {
  assert(workerPairs.size() >= tasks.threadCount() &&
         "Bvh::querySelf: build workerPairs from the TaskSystem that runs the query");
  for (int worker = 0; worker < workerPairs.size(); ++worker) workerPairs[worker].clear();
  // One task per block: the tasks differ in size by orders of magnitude, so the scheduler
  // balances them one by one. Which worker collects a pair depends on timing; the sort below
  // makes the result independent of it.
  tasks.parallelFor(static_cast<Index>(m_selfTasks.size()), 1,
                    [&](Index begin, Index end, int worker) {
                      for (Index t = begin; t < end; ++t) {
                        runSelfTask(m_selfTasks[t], filter, workerPairs[worker]);
                      }
                    });
  pairs.clear();
  for (int worker = 0; worker < workerPairs.size(); ++worker) {
    pairs.insert(pairs.end(), workerPairs[worker].begin(), workerPairs[worker].end());
  }
  detail::sortTrianglePairs(pairs, triangleCount());
}

namespace {

void crossPairs(const Bvh& treeA, Index a, const Bvh& treeB, Index b,
                std::vector<TrianglePair>& pairs) {
  const Bvh::Node& nodeA = treeA.nodes()[a];
  const Bvh::Node& nodeB = treeB.nodes()[b];
  if (!nodeA.bounds.overlaps(nodeB.bounds)) return;
  if (nodeA.isLeaf() && nodeB.isLeaf()) {
    for (Index i = nodeA.first; i < nodeA.first + nodeA.count; ++i) {
      for (Index j = nodeB.first; j < nodeB.first + nodeB.count; ++j) {
        if (treeA.slotBounds(i).overlaps(treeB.slotBounds(j))) {
          pairs.push_back({treeA.triangleOrder()[i], treeB.triangleOrder()[j]});
        }
      }
    }
    return;
  }
  const bool descendA =
      nodeB.isLeaf() || (!nodeA.isLeaf() && nodeA.bounds.halfSurfaceArea() >=
                                                nodeB.bounds.halfSurfaceArea());
  if (descendA) {
    crossPairs(treeA, nodeA.first, treeB, b, pairs);
    crossPairs(treeA, nodeA.first + 1, treeB, b, pairs);
  } else {
    crossPairs(treeA, a, treeB, nodeB.first, pairs);
    crossPairs(treeA, a, treeB, nodeB.first + 1, pairs);
  }
}

}  // namespace

void Bvh::queryPairs(const Bvh& other, std::vector<TrianglePair>& pairs) const {
  pairs.clear();
  if (m_nodes.empty() || other.m_nodes.empty()) return;
  crossPairs(*this, 0, other, 0, pairs);
  detail::sortTrianglePairs(pairs, std::max(triangleCount(), other.triangleCount()));
}

void Bvh::queryBox(const Aabb& box, std::vector<Index>& triangles) const {
  triangles.clear();
  if (m_nodes.empty()) return;
  // Depth-first with a fixed stack: a balanced tree over 2^32 triangles is < 64 levels deep and
  // the stack never holds more than one pending sibling per level.
  Index stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = m_nodes[stack[--top]];
    if (!node.bounds.overlaps(box)) continue;
    if (node.isLeaf()) {
      for (Index slot = node.first; slot < node.first + node.count; ++slot) {
        if (m_slotBounds[slot].overlaps(box)) triangles.push_back(m_triangleOrder[slot]);
      }
    } else {
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
  }
  std::sort(triangles.begin(), triangles.end());
}

}  // namespace weft
