// SelfIntersectionCounter: how many triangle pairs of a mesh intersect (the check behind the
// target "zero self-intersections in every frame"; the curtain runner's --check-intersections).
//
// Broad phase: the mesh's Bvh refit to the positions with zero thickness and queried for self
// pairs (pairs sharing a vertex are skipped there). Narrow phase: the exact triangle–triangle
// test (TriangleIntersection.h), so touching counts as intersecting.
//
// Limit: pairs of triangles that share a vertex are never counted, even when they also cross
// elsewhere (a fold pushed through a neighbouring triangle). Deciding those needs a test that
// excludes the shared vertex; it is not done here.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Bvh.h>

#include <span>
#include <vector>

namespace weft {

/// Counts intersecting triangle pairs of one mesh topology at changing positions.
class SelfIntersectionCounter {
 public:
  /// Prepares the counter for `triangleIndices` (three per triangle) over `restPositions`
  /// (which set the tree and the vertex count). Errors as Bvh::build.
  static Result<SelfIntersectionCounter> create(std::span<const Index> triangleIndices,
                                                std::span<const Vec3> restPositions);

  /// Number of pairs (i < j, no shared vertex) of triangles that intersect at `positions`
  /// (vertexCount() entries). Reuses its buffers: allocation-free after the first calls.
  Index count(std::span<const Vec3> positions);
  /// Clears `pairs`, then writes the intersecting pairs (sorted, first < second).
  void findIntersectingPairs(std::span<const Vec3> positions, std::vector<TrianglePair>& pairs);

  /// Number of vertices the positions must hold.
  Index vertexCount() const { return m_bvh.vertexCount(); }

 private:
  Bvh m_bvh;
  std::vector<TrianglePair> m_candidates;
};

}  // namespace weft
