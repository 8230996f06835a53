// Intersecting-pair counting: Bvh broad phase, exact triangle–triangle narrow phase.
#include <weft/collision/SelfIntersectionCounter.h>

#include <weft/collision/TriangleIntersection.h>

#include <utility>

namespace weft {

Result<SelfIntersectionCounter> SelfIntersectionCounter::create(
    std::span<const Index> triangleIndices, std::span<const Vec3> restPositions) {
  Result<Bvh> tree = Bvh::build(triangleIndices, restPositions);
  if (!tree) return tree.error();
  SelfIntersectionCounter counter;
  counter.m_bvh = std::move(tree).value();
  return counter;
}

void SelfIntersectionCounter::findIntersectingPairs(std::span<const Vec3> positions,
                                                    std::vector<TrianglePair>& pairs) {
  pairs.clear();
  m_bvh.refit(positions, 0.0);
  m_bvh.querySelf(m_candidates);
  for (const TrianglePair& candidate : m_candidates) {
    const std::array<Index, 3>& a = m_bvh.triangle(candidate.first);
    const std::array<Index, 3>& b = m_bvh.triangle(candidate.second);
    if (trianglesIntersect(positions[a[0]], positions[a[1]], positions[a[2]], positions[b[0]],
                           positions[b[1]], positions[b[2]])) {
      pairs.push_back(candidate);
    }
  }
}

Index SelfIntersectionCounter::count(std::span<const Vec3> positions) {
  m_bvh.refit(positions, 0.0);
  m_bvh.querySelf(m_candidates);
  Index intersecting = 0;
  for (const TrianglePair& candidate : m_candidates) {
    const std::array<Index, 3>& a = m_bvh.triangle(candidate.first);
    const std::array<Index, 3>& b = m_bvh.triangle(candidate.second);
    intersecting += trianglesIntersect(positions[a[0]], positions[a[1]], positions[a[2]],
                                       positions[b[0]], positions[b[1]], positions[b[2]]);
  }
  return intersecting;
}

}  // namespace weft
