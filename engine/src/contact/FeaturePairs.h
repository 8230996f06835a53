// FeaturePairs: the broad phase of the contact space — one AABB tree over every triangle of every
// cloth, refit per query, and the vertex–triangle and edge–edge feature pairs of the triangle
// pairs it reports (Bridson, Fedkiw & Anderson 2002, §6: the two kinds of pair that cover every
// way two triangle meshes can meet).
//
// A feature pair is reached through several triangle pairs; it is taken from one of them, its
// canonical pair (vertex v against triangle B: the lowest triangle around v that shares no vertex
// with B; edge a against edge b: the lowest pair of their triangles that shares none), so the
// features come out each once, in the sorted order of the triangle pairs, with no sort. A few
// feature pairs have no such triangle pair: every triangle of one feature touches every triangle
// of the other (a corner vertex against the triangle beside its only one). These neighbour pairs
// are listed once per build, from the mesh alone, and tested by their boxes after the rest. The tree
// query drops a triangle pair as it reports it when the pair cannot come within the margin over
// the step (trianglesMayComeWithin): on a fine mesh most overlapping boxes are neighbours moving
// together. The feature pairs are found in parallel over fixed blocks of triangle pairs and
// joined in block order: the same lists on any thread count.
#pragma once

#include "contact/ContactSpace.h"

#include <weft/collision/Bvh.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <array>
#include <initializer_list>
#include <memory>
#include <span>
#include <vector>

namespace weft {

/// Whether the boxes of two features' paths (the positions of vertices `first`, and of `second`,
/// from `from` to `to`) come within `reach` (m) of each other. When they do not, no point of one
/// feature comes that close to the other over the path, and the exact test need not run. Pass
/// the same positions as `from` and `to` for the features at one time. Always inlined, so that
/// the lists of vertices unroll: the narrow phase and the swept tests ask it for every pair.
[[gnu::always_inline]] inline bool featureBoxesWithin(std::initializer_list<Index> first,
                               std::initializer_list<Index> second, const Vec3Array& from,
                               const Vec3Array& to, Real reach) {
  Aabb a = Aabb::empty(), b = Aabb::empty();
  for (Index i : first) a.expand(Aabb::fromCorners(from[i], to[i]));
  for (Index i : second) b.expand(Aabb::fromCorners(from[i], to[i]));
  a.inflate(reach);
  return a.overlaps(b);
}

/// A triangle's motion over a step on straight lines: where its corners start, their mean move
/// and how far a corner's move is from that mean.
struct TriangleMotion {
  Vec3 centroid;  ///< m, of the start corners
  Vec3 shift;     ///< m, the mean of the corners' moves
  Real spread;    ///< m, the largest distance of a corner's move from the mean
};

/// The motion of the triangle whose corners move from `start` to `end`.
TriangleMotion triangleMotion(std::span<const Vec3, 3> start, std::span<const Vec3, 3> end);

/// Whether two triangles, starting at corners `startA` and `startB` and moving as `a` and `b`,
/// may come within `margin` (m) of each other along every axis at some time of the step. False
/// is a proof that they do not, by their gap along each axis and along the line between their
/// centroids: pairs moving together are dismissed however far they travel, where the boxes of
/// their paths would overlap.
bool trianglesMayComeWithin(const TriangleMotion& a, std::span<const Vec3, 3> startA,
                            const TriangleMotion& b, std::span<const Vec3, 3> startB, Real margin);

class FeaturePairs {
 public:
  /// Builds the tree over the space's triangles at its current positions, the adjacency tables
  /// and the neighbour pairs; allocates (call when the space is rebuilt).
  void build(const ContactSpace& space, TaskSystem* tasks);

  /// m: leaves whose triangles moved less than this since their last refit keep their boxes
  /// (Bvh::setRefitMargin; the pairs found do not change). Negative: refit everything.
  void setRefitMargin(Real margin) { m_bvh.setRefitMargin(margin); }

  /// Whether find() with `dirty` searches around the dirty triangles alone (few of them), rather
  /// than querying the whole tree and keeping the pairs with a dirty vertex.
  static bool searchesLocally(const ContactSpace& space, const std::vector<char>& dirty);
  /// The feature pairs whose boxes over `from` → `to` (one side inflated by `inflate`) overlap,
  /// in triangle pairs the space allows (ContactSpace::pairsAllowed). With `dirty` (one flag per
  /// vertex), only the pairs with a dirty vertex.
  void find(const ContactSpace& space, const Vec3Array& from, const Vec3Array& to, Real inflate,
            const std::vector<char>* dirty = nullptr);

  /// (vertex, triangle) and (edge, edge) pairs of the last find(), each once: those reached
  /// through triangle pairs, then the neighbour pairs.
  const std::vector<std::array<Index, 2>>& vertexTriangle() const { return m_vertexTriangle; }
  const std::vector<std::array<Index, 2>>& edgeEdge() const { return m_edgeEdge; }

  /// Tree nodes the refits recomputed and kept since the last call; resets the counts.
  Bvh::RefitCounts takeRefitCounts() {
    const Bvh::RefitCounts counts = m_refitCounts;
    m_refitCounts = {};
    return counts;
  }

 private:
  void boxFeatures(const ContactSpace& space, const Vec3Array& from, const Vec3Array& to);
  // Whether triangles first < second are allowed to meet and may come within `margin` over the
  // step (the motions of boxFeatures()); only reads, so every worker of a query may ask at once.
  bool mayTouch(const ContactSpace& space, const Vec3Array& from, Real margin, Index first,
                Index second) const;
  void findTrianglePairs(const ContactSpace& space, const Vec3Array& from, const Vec3Array& to,
                         Real inflate, const std::vector<char>* dirty);
  // The feature pairs of the triangle pairs found (their boxes from boxFeatures()).
  void collect(const ContactSpace& space, Real margin, const std::vector<char>* dirty);
  // The feature pairs that no pair of their triangles sharing no vertex reaches, from the mesh.
  void listNeighbourPairs(const ContactSpace& space);
  // Appends the neighbour pairs whose boxes come within `margin`.
  void collectNeighbourPairs(const ContactSpace& space, Real margin, const std::vector<char>* dirty);

  TaskSystem* m_tasks = nullptr;
  Bvh m_bvh;
  Bvh::RefitCounts m_refitCounts;
  std::unique_ptr<PerWorker<std::vector<TrianglePair>>> m_workerPairs;
  std::vector<TrianglePair> m_trianglePairs;
  std::vector<Index> m_boxHits;
  std::vector<char> m_dirtyTriangle;
  std::vector<Index> m_vertexTriangleBegin, m_vertexTriangles;  // triangles around each vertex
  std::vector<std::array<Index, 2>> m_edgeTriangles;  // the triangles of each edge
  std::vector<Aabb> m_vertexBoxes, m_triangleBoxes, m_edgeBoxes;
  std::vector<TriangleMotion> m_triangleMotions;  // per triangle, over the step of boxFeatures()
  struct BlockFeatures {
    std::vector<std::array<Index, 2>> vertexTriangle, edgeEdge;
  };
  std::vector<BlockFeatures> m_blockFeatures;
  std::vector<std::array<Index, 2>> m_vertexTriangle, m_edgeEdge;
  std::vector<std::array<Index, 2>> m_neighbourVertexTriangle, m_neighbourEdgeEdge;
};

}  // namespace weft
