// Triangle–triangle and segment–triangle intersection tests with exact orientation signs.
//
// Design note
// -----------
// Used to count intersecting triangle pairs (the "zero self-intersections" target), where a
// wrong answer either hides a tunnelling bug or reports one that is not there.
//
// Method. Two closed triangles intersect exactly when an edge of one meets the other triangle
// (6 segment–triangle tests): if they cross, the ends of their intersection segment lie on edges;
// if they are coplanar and overlap, either edges cross or one triangle holds the other's edges.
// Segment–triangle uses only signs of orientation determinants:
//   * the segment's ends on strictly the same side of the plane → no;
//   * both ends in the plane → the coplanar 2D test below;
//   * otherwise the line pq meets the closed triangle exactly when orient3d(p, q, a, b),
//     orient3d(p, q, b, c) and orient3d(p, q, c, a) do not have strictly opposite signs.
// Coplanar configurations are projected onto the coordinate plane that drops the largest
// component of the triangle normal (exact: dropping a coordinate moves no point), then tested
// in 2D: an end of the segment inside the triangle, or the segment crossing an edge (closed,
// collinear overlaps included).
//
// Exactness. Every sign comes from exact predicates (orient2d, orient3d: a double filter with
// Shewchuk's error bound, then exact expansion arithmetic), so the answer is exact for the
// given double coordinates: touching counts as intersecting (triangles are closed sets), a
// vertex one ulp off the other triangle's plane does not. Rejected: Möller's interval test in
// floating point (its divisions make the coplanar-ish cases go either way) and epsilons
// (they turn near misses into hits, which the intersection count must not do).
//
// Limits. A degenerate (zero-area) triangle is tested as the union of its edges through the
// segment–segment closest-point distance being exactly zero, which is not exact; cloth
// validation rejects such triangles anyway. Overflow and underflow are not handled (coordinates
// far beyond ±1e100 or products below 1e-300).
#pragma once

#include <weft/Math.h>

namespace weft {

/// True when the closed segment pq and the closed triangle abc share a point (exact signs).
bool segmentIntersectsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                               const Vec3& c);

/// True when the closed triangles (a0, a1, a2) and (b0, b1, b2) share a point (exact signs;
/// touching counts).
bool trianglesIntersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                        const Vec3& b1, const Vec3& b2);

}  // namespace weft
