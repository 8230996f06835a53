#include "contact/FeaturePairs.h"

#include <weft/threading/GrainSizes.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace weft {
namespace {

// Candidate triangle pairs per parallel block when collecting feature pairs: a few box tests
// each, ~50–100 ns, so 256 pairs are ~15–25 µs of work.
constexpr TaskSystem::Index kGrainTrianglePairs = 256;
// Above one dirty triangle in this many, one self query (filtered) is cheaper than a box query
// per dirty triangle: a box query visits a few dozen nodes, a self query every overlapping pair.
constexpr Index kBoxQueriesPerSelfQuery = 8;

// Whether `dirtyTriangles` of `triangles` are few enough for a box query each.
bool boxQueriesPay(Index dirtyTriangles, Index triangles) {
  return dirtyTriangles * kBoxQueriesPerSelfQuery <= triangles;
}

}  // namespace

void FeaturePairs::build(const ContactSpace& space, TaskSystem* tasks) {
  m_tasks = tasks;
  if (m_tasks && !m_workerPairs) {
    m_workerPairs = std::make_unique<PerWorker<std::vector<TrianglePair>>>(*m_tasks);
  }
  std::vector<Index> indices;
  indices.reserve(3 * space.triangles.size());
  for (const auto& triangle : space.triangles) indices.insert(indices.end(), triangle.begin(), triangle.end());
  // The tree groups triangles by their rest shape, which keeps leaves coherent as the cloth
  // deforms; each cloth's rest shape is laid beside the others' so that no leaf mixes cloths.
  Vec3Array layout(space.rest.size());
  Real shift = 0;
  std::size_t begin = 0;
  while (begin < space.rest.size()) {
    std::size_t end = begin;
    Aabb box = Aabb::empty();
    while (end < space.rest.size() && space.owner[end] == space.owner[begin]) box.expand(space.rest[end++]);
    for (std::size_t i = begin; i < end; ++i) layout[i] = space.rest[i] + Vec3(shift - box.min.x(), 0, 0);
    shift += (box.max.x() - box.min.x()) + 1;
    begin = end;
  }
  const Real margin = m_bvh.refitMargin();
  m_bvh = Bvh::build(indices, layout).value();
  m_bvh.setRefitMargin(margin);

  const Index vertexCount = space.vertexCount();
  m_vertexTriangleBegin.assign(vertexCount + 1, 0);
  for (const auto& triangle : space.triangles) {
    for (Index vertex : triangle) ++m_vertexTriangleBegin[vertex + 1];
  }
  for (Index i = 0; i < vertexCount; ++i) m_vertexTriangleBegin[i + 1] += m_vertexTriangleBegin[i];
  m_vertexTriangles.resize(m_vertexTriangleBegin[vertexCount]);
  std::vector<Index> fill(m_vertexTriangleBegin.begin(), m_vertexTriangleBegin.end() - 1);
  for (Index t = 0; t < Index(space.triangles.size()); ++t) {
    for (Index vertex : space.triangles[t]) m_vertexTriangles[fill[vertex]++] = t;
  }
  m_edgeTriangles.assign(space.edges.size(), {kInvalidIndex, kInvalidIndex});
  for (Index t = 0; t < Index(space.triangleEdges.size()); ++t) {
    for (Index edge : space.triangleEdges[t]) {
      std::array<Index, 2>& slots = m_edgeTriangles[edge];
      (slots[0] == kInvalidIndex ? slots[0] : slots[1]) = t;
    }
  }
  m_vertexBoxes.resize(vertexCount);
  m_triangleBoxes.resize(space.triangles.size());
  m_triangleMotions.resize(space.triangles.size());
  m_edgeBoxes.resize(space.edges.size());
  listNeighbourPairs(space);
}

void FeaturePairs::listNeighbourPairs(const ContactSpace& space) {
  // Only a feature whose triangles all touch a triangle of the other feature can be one: the
  // candidates lie among the triangles around the corners of its own triangles.
  const auto& triangles = space.triangles;
  auto shares = [&](Index a, Index b) { return trianglesShareVertex(triangles[a], triangles[b]); };
  auto around = [&](Index vertex) {
    return std::span<const Index>(m_vertexTriangles.data() + m_vertexTriangleBegin[vertex],
                                  m_vertexTriangles.data() + m_vertexTriangleBegin[vertex + 1]);
  };
  // Pairs that are neighbours at rest (ContactSpace::restNeighbours), which the narrow phase
  // never makes a contact, are left out, so the impact pass's swept test never meets them
  // either: a sliver's tip lies within rounding of the next triangle, which that test reads as
  // a hit at the start.
  std::vector<Index> candidates;
  auto gatherTouching = [&](std::span<const Index> own) {
    candidates.clear();
    for (Index t : own) {
      for (Index corner : triangles[t]) {
        for (Index other : around(corner)) candidates.push_back(other);
      }
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  };
  m_neighbourVertexTriangle.clear();
  for (Index vertex = 0; vertex < space.vertexCount(); ++vertex) {
    const std::span<const Index> own = around(vertex);
    gatherTouching(own);
    for (Index triangle : candidates) {
      const auto& c = triangles[triangle];
      if (c[0] == vertex || c[1] == vertex || c[2] == vertex || space.restNeighbours(vertex, c)) {
        continue;
      }
      if (std::all_of(own.begin(), own.end(), [&](Index t) { return shares(t, triangle); })) {
        m_neighbourVertexTriangle.push_back({vertex, triangle});
      }
    }
  }
  m_neighbourEdgeEdge.clear();
  std::vector<Index> ownTriangles, edgeCandidates;
  for (Index a = 0; a < Index(space.edges.size()); ++a) {
    ownTriangles.clear();
    for (Index t : m_edgeTriangles[a]) {
      if (t != kInvalidIndex) ownTriangles.push_back(t);
    }
    gatherTouching(ownTriangles);
    edgeCandidates.clear();
    for (Index t : candidates) {
      for (Index b : space.triangleEdges[t]) {
        if (b > a) edgeCandidates.push_back(b);
      }
    }
    std::sort(edgeCandidates.begin(), edgeCandidates.end());
    edgeCandidates.erase(std::unique(edgeCandidates.begin(), edgeCandidates.end()),
                         edgeCandidates.end());
    const auto& p = space.edges[a];
    for (Index b : edgeCandidates) {
      const auto& q = space.edges[b];
      if (p[0] == q[0] || p[0] == q[1] || p[1] == q[0] || p[1] == q[1]) continue;
      if (space.restNeighbours(p, q)) continue;
      bool reached = false;
      for (Index ta : ownTriangles) {
        for (Index tb : m_edgeTriangles[b]) reached = reached || (tb != kInvalidIndex && !shares(ta, tb));
      }
      if (!reached) m_neighbourEdgeEdge.push_back({a, b});
    }
  }
}

TriangleMotion triangleMotion(std::span<const Vec3, 3> start, std::span<const Vec3, 3> end) {
  TriangleMotion motion;
  motion.centroid = (start[0] + start[1] + start[2]) / 3;
  const Vec3 moves[3] = {end[0] - start[0], end[1] - start[1], end[2] - start[2]};
  motion.shift = (moves[0] + moves[1] + moves[2]) / 3;
  motion.spread = std::max({(moves[0] - motion.shift).norm(), (moves[1] - motion.shift).norm(),
                            (moves[2] - motion.shift).norm()});
  return motion;
}

bool trianglesMayComeWithin(const TriangleMotion& a, std::span<const Vec3, 3> startA,
                            const TriangleMotion& b, std::span<const Vec3, 3> startB, Real margin) {
  // Over the step, a point of a lies within its start shape moved by t·a.shift and grown by
  // a.spread (t in [0, 1]): the gap along any direction shrinks by at most the shifts'
  // difference along it and both spreads.
  const auto low = [](std::span<const Vec3, 3> c, int k) { return std::min({c[0][k], c[1][k], c[2][k]}); };
  const auto high = [](std::span<const Vec3, 3> c, int k) { return std::max({c[0][k], c[1][k], c[2][k]}); };
  const Real spread = a.spread + b.spread;
  for (int k = 0; k < 3; ++k) {
    const Real gap = std::max(low(startB, k) - high(startA, k), low(startA, k) - high(startB, k));
    if (gap - std::abs(b.shift[k] - a.shift[k]) - spread > margin) return false;
  }
  // Along the line between the centroids, which parts triangles of a grid whose boxes overlap
  // (neighbours across a diagonal). Pairs within the margin along every axis are within √3 times
  // the margin of each other, so that is the margin along this line.
  Vec3 axis = b.centroid - a.centroid;
  const Real length = axis.norm();
  if (!(length > 0)) return true;
  axis /= length;
  const Real endOfA = std::max({startA[0].dot(axis), startA[1].dot(axis), startA[2].dot(axis)});
  const Real startOfB = std::min({startB[0].dot(axis), startB[1].dot(axis), startB[2].dot(axis)});
  const Real approach = std::abs((b.shift - a.shift).dot(axis)) + spread;
  return !(startOfB - endOfA - approach > std::numbers::sqrt3 * margin);
}

void FeaturePairs::boxFeatures(const ContactSpace& space, const Vec3Array& from,
                               const Vec3Array& to) {
  // Every vertex's, triangle's and edge's box over the step, and every triangle's motion, once.
  const auto& triangles = space.triangles;
  const auto& edges = space.edges;
  const Index vertexCount = space.vertexCount();
  const Index triangleCount = Index(triangles.size()), edgeCount = Index(edges.size());
  auto boxVertices = [&](Index begin, Index end, int) {
    for (Index i = begin; i < end; ++i) m_vertexBoxes[i] = Aabb::fromCorners(from[i], to[i]);
  };
  auto boxElements = [&](Index begin, Index end, int) {
    for (Index i = begin; i < end; ++i) {
      if (i < triangleCount) {
        const auto& c = triangles[i];
        Aabb box = m_vertexBoxes[c[0]];
        box.expand(m_vertexBoxes[c[1]]);
        box.expand(m_vertexBoxes[c[2]]);
        m_triangleBoxes[i] = box;
        const std::array<Vec3, 3> start{from[c[0]], from[c[1]], from[c[2]]};
        const std::array<Vec3, 3> end{to[c[0]], to[c[1]], to[c[2]]};
        m_triangleMotions[i] = triangleMotion(start, end);
      } else {
        const auto& c = edges[i - triangleCount];
        Aabb box = m_vertexBoxes[c[0]];
        box.expand(m_vertexBoxes[c[1]]);
        m_edgeBoxes[i - triangleCount] = box;
      }
    }
  };
  if (m_tasks) {
    m_tasks->parallelFor(vertexCount, kGrainVertices, boxVertices);
    m_tasks->parallelFor(triangleCount + edgeCount, kGrainVertices, boxElements);
  } else {
    boxVertices(0, vertexCount, 0);
    boxElements(0, triangleCount + edgeCount, 0);
  }
}

bool FeaturePairs::mayTouch(const ContactSpace& space, const Vec3Array& from, Real margin,
                            Index first, Index second) const {
  const auto& a = space.triangles[first];
  const auto& b = space.triangles[second];
  if (!space.pairsAllowed(a[0], b[0])) return false;
  const std::array<Vec3, 3> startA{from[a[0]], from[a[1]], from[a[2]]};
  const std::array<Vec3, 3> startB{from[b[0]], from[b[1]], from[b[2]]};
  return trianglesMayComeWithin(m_triangleMotions[first], startA, m_triangleMotions[second],
                                startB, margin);
}

bool FeaturePairs::searchesLocally(const ContactSpace& space, const std::vector<char>& dirty) {
  Index dirtyTriangles = 0;
  for (const std::array<Index, 3>& c : space.triangles) {
    dirtyTriangles += (dirty[c[0]] | dirty[c[1]] | dirty[c[2]]) != 0;
  }
  return boxQueriesPay(dirtyTriangles, Index(space.triangles.size()));
}

void FeaturePairs::findTrianglePairs(const ContactSpace& space, const Vec3Array& from,
                                     const Vec3Array& to, Real inflate,
                                     const std::vector<char>* dirty) {
  WEFT_PROFILE_ZONE("broad phase");
  // Two boxes each grown by half the margin overlap where the boxes come within the margin, the
  // reach collect() asks for (one side grown by all of it); grown by all of it, the tree would
  // report pairs up to twice as far apart. The part per million over a half keeps every pair
  // collect() takes despite the rounding of the two sums.
  m_bvh.refit(from, to, Real(0.5 + 1e-6) * inflate, m_tasks);
  m_refitCounts.refitNodes += m_bvh.lastRefitCounts().refitNodes;
  m_refitCounts.skippedNodes += m_bvh.lastRefitCounts().skippedNodes;
  Index dirtyTriangles = 0;
  if (dirty) {
    m_dirtyTriangle.resize(space.triangles.size());
    for (std::size_t t = 0; t < space.triangles.size(); ++t) {
      const auto& c = space.triangles[t];
      m_dirtyTriangle[t] = (*dirty)[c[0]] | (*dirty)[c[1]] | (*dirty)[c[2]];
      dirtyTriangles += m_dirtyTriangle[t] != 0;
    }
  }
  // Pairs the space does not allow, and pairs that cannot come within the margin over the step
  // (trianglesMayComeWithin), are dropped as the tree reports them: most overlapping boxes on a
  // fine mesh belong to neighbours that move together, and dropping them there spares their
  // merge, sort and scan.
  struct FilterContext {
    const FeaturePairs* pairs;
    const ContactSpace* space;
    const Vec3Array* from;
    Real margin;
  } context{this, &space, &from, inflate};
  const TrianglePairFilter filter{
      [](const void* opaque, Index a, Index b) {
        const auto& c = *static_cast<const FilterContext*>(opaque);
        return c.pairs->mayTouch(*c.space, *c.from, c.margin, a, b);
      },
      &context};
  if (dirty && boxQueriesPay(dirtyTriangles, Index(space.triangles.size()))) {
    // Each dirty triangle's own box against the tree: the pairs the self query would report
    // with it (the same leaf test), a pair of two dirty triangles taken from its lower one.
    m_trianglePairs.clear();
    const std::vector<Index>& order = m_bvh.triangleOrder();
    for (Index slot = 0; slot < Index(order.size()); ++slot) {
      const Index triangle = order[slot];
      if (!m_dirtyTriangle[triangle]) continue;
      m_bvh.queryBox(m_bvh.slotBounds(slot), m_boxHits);
      for (Index other : m_boxHits) {
        if (other == triangle || (m_dirtyTriangle[other] && other < triangle)) continue;
        if (trianglesShareVertex(space.triangles[triangle], space.triangles[other])) continue;
        const TrianglePair pair{std::min(triangle, other), std::max(triangle, other)};
        if (mayTouch(space, from, inflate, pair.first, pair.second)) {
          m_trianglePairs.push_back(pair);
        }
      }
    }
    std::sort(m_trianglePairs.begin(), m_trianglePairs.end());
  } else if (m_tasks && m_workerPairs) {
    m_bvh.querySelf(m_trianglePairs, *m_tasks, *m_workerPairs, filter);
    // Which worker finds which pairs depends on scheduling: room for all in every worker's
    // list, so allocation follows the number of pairs, never the timing of the threads.
    const std::size_t total = m_trianglePairs.size();
    m_workerPairs->forEach([total](std::vector<TrianglePair>& list) {
      if (list.capacity() < total) list.reserve(total);
    });
  } else {
    m_bvh.querySelf(m_trianglePairs, filter);
  }
  if (dirty) {
    std::erase_if(m_trianglePairs, [&](const TrianglePair& pair) {
      return !m_dirtyTriangle[pair.first] && !m_dirtyTriangle[pair.second];
    });
  }
}

void FeaturePairs::find(const ContactSpace& space, const Vec3Array& from, const Vec3Array& to,
                        Real inflate, const std::vector<char>* dirty) {
  boxFeatures(space, from, to);
  findTrianglePairs(space, from, to, inflate, dirty);
  collect(space, inflate, dirty);
}

void FeaturePairs::collect(const ContactSpace& space, Real margin,
                           const std::vector<char>* dirty) {
  WEFT_PROFILE_ZONE("feature pairs");
  const auto& triangles = space.triangles;
  const auto& edges = space.edges;
  auto shares = [&](Index a, Index b) { return trianglesShareVertex(triangles[a], triangles[b]); };
  // Canonical ownership (see the file comment), tested cheaply: stop at the first candidate
  // that beats the pair at hand.
  auto isVertexOwner = [&](Index vertex, Index owner, Index triangle) {
    for (Index k = m_vertexTriangleBegin[vertex]; k < m_vertexTriangleBegin[vertex + 1]; ++k) {
      const Index candidate = m_vertexTriangles[k];
      if (candidate == owner) return true;
      if (!shares(candidate, triangle)) return false;
    }
    return false;
  };
  auto isEdgeOwner = [&](Index a, Index b, const TrianglePair& pair) {
    bool listed = false;
    for (Index ta : m_edgeTriangles[a]) {
      for (Index tb : m_edgeTriangles[b]) {
        if (ta == kInvalidIndex || tb == kInvalidIndex) continue;
        const TrianglePair candidate{std::min(ta, tb), std::max(ta, tb)};
        if (candidate < pair && !shares(ta, tb)) return false;
        listed = listed || candidate == pair;
      }
    }
    return listed;
  };
  auto isDirty = [&](Index vertex) { return !dirty || (*dirty)[vertex]; };
  auto collectRange = [&](Index begin, Index end, std::vector<std::array<Index, 2>>& vertexTriangle,
                          std::vector<std::array<Index, 2>>& edgeEdge) {
    for (Index k = begin; k < end; ++k) {
      const TrianglePair& pair = m_trianglePairs[k];
      const Aabb& firstBox = m_triangleBoxes[pair.first];
      const Aabb& secondBox = m_triangleBoxes[pair.second];
      // Every feature box of a triangle lies in its box: when the inflated triangle box misses
      // the other triangle's, so does every test of that side.
      Aabb firstReach = firstBox, secondReach = secondBox;
      firstReach.inflate(margin);
      secondReach.inflate(margin);
      const bool firstReaches = firstReach.overlaps(secondBox);
      const bool secondReaches = secondReach.overlaps(firstBox);
      if (!firstReaches && !secondReaches) continue;
      const auto addVertexContacts = [&](Index fromTriangle, Index toTriangle, const Aabb& toBox) {
        const auto& target = triangles[toTriangle];
        const bool targetDirty = isDirty(target[0]) || isDirty(target[1]) || isDirty(target[2]);
        for (Index vertex : triangles[fromTriangle]) {
          Aabb box = m_vertexBoxes[vertex];
          box.inflate(margin);
          if (box.overlaps(toBox) && (targetDirty || isDirty(vertex)) &&
              isVertexOwner(vertex, fromTriangle, toTriangle)) {
            vertexTriangle.push_back({vertex, toTriangle});
          }
        }
      };
      if (firstReaches) addVertexContacts(pair.first, pair.second, secondBox);
      if (secondReaches) addVertexContacts(pair.second, pair.first, firstBox);
      if (!firstReaches) continue;
      const auto& secondEdges = space.triangleEdges[pair.second];
      for (Index a : space.triangleEdges[pair.first]) {
        Aabb first = m_edgeBoxes[a];
        first.inflate(margin);
        if (!first.overlaps(secondBox)) continue;
        for (Index b : secondEdges) {
          if (first.overlaps(m_edgeBoxes[b]) &&
              (isDirty(edges[a][0]) || isDirty(edges[a][1]) || isDirty(edges[b][0]) ||
               isDirty(edges[b][1])) &&
              isEdgeOwner(a, b, pair)) {
            edgeEdge.push_back({std::min(a, b), std::max(a, b)});
          }
        }
      }
    }
  };
  m_vertexTriangle.clear();
  m_edgeEdge.clear();
  const Index pairCount = Index(m_trianglePairs.size());
  if (!m_tasks || m_tasks->isSerial() || pairCount <= kGrainTrianglePairs) {
    collectRange(0, pairCount, m_vertexTriangle, m_edgeEdge);
  } else {
    const Index blocks = TaskSystem::blockCount(pairCount, kGrainTrianglePairs);
    if (m_blockFeatures.size() < blocks) m_blockFeatures.resize(blocks);
    m_tasks->parallelFor(pairCount, kGrainTrianglePairs, [&](Index begin, Index end, int) {
      BlockFeatures& block = m_blockFeatures[begin / kGrainTrianglePairs];
      block.vertexTriangle.clear();
      block.edgeEdge.clear();
      collectRange(begin, end, block.vertexTriangle, block.edgeEdge);
    });
    for (Index b = 0; b < blocks; ++b) {
      const BlockFeatures& block = m_blockFeatures[b];
      m_vertexTriangle.insert(m_vertexTriangle.end(), block.vertexTriangle.begin(),
                              block.vertexTriangle.end());
      m_edgeEdge.insert(m_edgeEdge.end(), block.edgeEdge.begin(), block.edgeEdge.end());
    }
  }
  collectNeighbourPairs(space, margin, dirty);
}

void FeaturePairs::collectNeighbourPairs(const ContactSpace& space, Real margin,
                                         const std::vector<char>* dirty) {
  // Few (about one per boundary vertex of a grid), so one serial pass.
  auto isDirty = [&](Index vertex) { return !dirty || (*dirty)[vertex]; };
  for (const auto& [vertex, triangle] : m_neighbourVertexTriangle) {
    const auto& c = space.triangles[triangle];
    if (!space.pairsAllowed(vertex, c[0])) continue;
    Aabb box = m_vertexBoxes[vertex];
    box.inflate(margin);
    if (box.overlaps(m_triangleBoxes[triangle]) &&
        (isDirty(vertex) || isDirty(c[0]) || isDirty(c[1]) || isDirty(c[2]))) {
      m_vertexTriangle.push_back({vertex, triangle});
    }
  }
  for (const auto& [a, b] : m_neighbourEdgeEdge) {
    const auto& p = space.edges[a];
    const auto& q = space.edges[b];
    if (!space.pairsAllowed(p[0], q[0])) continue;
    Aabb box = m_edgeBoxes[a];
    box.inflate(margin);
    if (box.overlaps(m_edgeBoxes[b]) &&
        (isDirty(p[0]) || isDirty(p[1]) || isDirty(q[0]) || isDirty(q[1]))) {
      m_edgeEdge.push_back({a, b});
    }
  }
}

}  // namespace weft
