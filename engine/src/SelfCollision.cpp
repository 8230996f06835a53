#include "SelfCollision.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <unordered_map>

namespace weft {
namespace {

// findTrianglePairsTouching: above one marked triangle in this many, the full self query
// (filtered) is used instead of one box query per marked triangle. A box query visits a few
// dozen nodes, a self query all overlapping node pairs of the tree. An estimate of the
// break-even, not measured (results are the same either way; only the cost changes).
constexpr Index kBoxQueriesPerSelfQuery = 8;

}  // namespace

void buildEdgeTables(const ClothModel& model, std::vector<std::array<Index, 2>>& edges,
                     std::vector<std::array<Index, 3>>& triangleEdges) {
  edges.clear();
  std::unordered_map<std::uint64_t, Index> edgeOfKey;
  for (Index e = 0; e < model.edges().size(); ++e) {
    const auto& vertices = model.edges()[e].vertices;
    edges.push_back(vertices);
    edgeOfKey[(std::uint64_t(vertices[0]) << 32) | vertices[1]] = e;
  }
  const std::vector<Index>& indices = model.indices();
  triangleEdges.resize(model.triangleCount());
  for (Index t = 0; t < model.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      Index a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
      if (a > b) std::swap(a, b);
      triangleEdges[t][k] = edgeOfKey.at((std::uint64_t(a) << 32) | b);
    }
  }
}

SelfCollision::SelfCollision(const ClothModel& model, TaskSystem* tasks) : ContactResolver(tasks) {
  if (m_tasks) m_workerPairs = std::make_unique<PerWorker<std::vector<TrianglePair>>>(*m_tasks);
  m_bvh = Bvh::build(model.indices(), model.restPositions()).value();
  m_sweptBvh = m_bvh;
  std::vector<std::array<Index, 3>> triangles(model.triangleCount());
  for (Index t = 0; t < model.triangleCount(); ++t) triangles[t] = m_bvh.triangle(t);
  std::vector<std::array<Index, 2>> edges;
  std::vector<std::array<Index, 3>> triangleEdges;
  buildEdgeTables(model, edges, triangleEdges);
  setTopology(std::move(triangles), std::move(triangleEdges), std::move(edges),
              model.restPositions(), std::vector<Index>(model.vertexCount(), 0));
  // The proximity broad phase below reads nothing but its arguments.
  setBroadPhaseIsPure(true);
}

void SelfCollision::findTrianglePairs(const Vec3Array& from, const Vec3Array& to, Real inflate,
                                      bool proximity, std::vector<TrianglePair>& pairs) {
  WEFT_PROFILE_ZONE("broad phase");
  Bvh& bvh = proximity ? m_bvh : m_sweptBvh;
  bvh.refit(from, to, inflate, m_tasks);
  m_refitCounts.refitNodes += bvh.lastRefitCounts().refitNodes;
  m_refitCounts.skippedNodes += bvh.lastRefitCounts().skippedNodes;
  if (m_tasks && m_workerPairs) {
    bvh.querySelf(pairs, *m_tasks, *m_workerPairs);
    // Which worker finds which pairs depends on scheduling, so a worker's list may need any
    // share of the total: give each room for all of it, so that allocation follows the number
    // of pairs (which grows only with contact) and never the timing of the threads.
    const std::size_t total = pairs.size();
    m_workerPairs->forEach([total](std::vector<TrianglePair>& list) {
      if (list.capacity() < total) list.reserve(total);
    });
  } else {
    bvh.querySelf(pairs);
  }
}

void SelfCollision::findTrianglePairsTouching(const Vec3Array& from, const Vec3Array& to,
                                              Real inflate, const std::vector<char>& marked,
                                              std::vector<TrianglePair>& pairs) {
  Index markedCount = 0;
  for (char flag : marked) markedCount += flag != 0;
  // Many marked triangles: one self query is cheaper than a box query for each.
  if (markedCount * kBoxQueriesPerSelfQuery > Index(marked.size())) {
    ContactResolver::findTrianglePairsTouching(from, to, inflate, marked, pairs);
    return;
  }
  WEFT_PROFILE_ZONE("broad phase (marked)");
  m_sweptBvh.refit(from, to, inflate, m_tasks);
  m_refitCounts.refitNodes += m_sweptBvh.lastRefitCounts().refitNodes;
  m_refitCounts.skippedNodes += m_sweptBvh.lastRefitCounts().skippedNodes;
  // Each marked triangle's own box against the tree: the pairs the self query would report with
  // it (the same box-overlap test at the leaves), found from the marked side. A pair of two
  // marked triangles is taken from its lower one.
  pairs.clear();
  const std::vector<Index>& order = m_sweptBvh.triangleOrder();
  for (Index slot = 0; slot < order.size(); ++slot) {
    const Index triangle = order[slot];
    if (!marked[triangle]) continue;
    m_sweptBvh.queryBox(m_sweptBvh.slotBounds(slot), m_boxHits);
    const std::array<Index, 3>& a = m_sweptBvh.triangle(triangle);
    for (Index other : m_boxHits) {
      if (other == triangle || (marked[other] && other < triangle)) continue;
      const std::array<Index, 3>& b = m_sweptBvh.triangle(other);
      bool shared = false;
      for (Index i : a) shared = shared || i == b[0] || i == b[1] || i == b[2];
      if (shared) continue;
      pairs.push_back({std::min(triangle, other), std::max(triangle, other)});
    }
  }
  std::sort(pairs.begin(), pairs.end());
}

void SelfCollision::setRefitSkipping(Real motion) {
  m_bvh.setRefitMargin(motion);
  m_sweptBvh.setRefitMargin(motion);
}

SelfCollisionReport SelfCollision::resolve(const Vec3Array& start, Real h, Real thickness,
                                           Real friction, const std::vector<Real>& inverseMasses,
                                           Vec3Array& x, Vec3Array& v,
                                           std::span<const ColliderFrame> colliders) {
  WEFT_PROFILE_ZONE("self collision");
  const ContactOwner owner{thickness, friction};
  setColliders(colliders);
  const SelfCollisionReport report = ContactResolver::resolve(
      start, h, std::span<const ContactOwner>(&owner, 1), inverseMasses, ContactOptions{}, x, v);
  setColliders({});
  return report;
}

}  // namespace weft
