// Closest-point kernels: point–triangle, segment–segment (edge–edge) and segment–triangle.
//
// Design note
// -----------
// These are the distance queries of the proximity stage (repulsion within the cloth thickness,
// Bridson, Fedkiw & Anderson 2002, §6) and of the proximity check at the roots found by the
// continuous tests. Both are pure functions of a few points and are tested alone against brute
// force sampling.
//
// Point–triangle: the classic Voronoi-region walk (vertex regions, then edge regions, then the
// face), written with dot products of edge vectors so that the returned barycentric weights are
// exactly 0 or 1 on the boundary features: the caller can tell a vertex, edge or face contact
// apart with ==. A degenerate triangle (|ab × ac|² below 1e-12 × longest edge⁴, i.e. a sliver
// whose face region cannot be computed reliably) falls back to the closest of its three edges.
//
// Segment–segment: minimise |p(s) − q(u)|² over [0,1]², clamping one parameter and re-solving
// for the other. Nearly parallel segments (sin² of the angle below 1e-12) have no unique
// closest pair; the middle of the overlap of their projections is chosen, so the answer is
// symmetric and stable under tiny rotations instead of jumping between the two ends. Zero-length
// segments are points.
//
// Segment–triangle (a capsule's core against a cloth triangle, the face contacts): a segment
// that crosses the closed triangle is at distance 0 there; otherwise the closest pair has a
// point on the boundary of one of the two, so it is the nearest of the segment's two ends
// against the triangle and the segment against the triangle's three edges (five queries of the
// kernels above). Ties go to the first found in that order, so the answer is deterministic.
#pragma once

#include <weft/Math.h>

namespace weft {

/// The closest point of a triangle to a query point.
struct TriangleClosestPoint {
  Vec3 point;        ///< m, closest point on the (closed) triangle
  Vec3 barycentric;  ///< weights of corners a, b, c: point = w0·a + w1·b + w2·c, each in [0, 1]
  Real distance = 0; ///< m, |query − point|
};

/// Closest point on triangle (a, b, c) to `point`, with barycentric weights (exact 0 and 1 on
/// edges and corners).
TriangleClosestPoint closestPointOnTriangle(const Vec3& point, const Vec3& a, const Vec3& b,
                                            const Vec3& c);

/// The closest points of two segments.
struct SegmentClosestPoints {
  Real firstParameter = 0;   ///< s in [0, 1]: pointOnFirst = (1 − s)·p0 + s·p1
  Real secondParameter = 0;  ///< u in [0, 1]: pointOnSecond = (1 − u)·q0 + u·q1
  Vec3 pointOnFirst;         ///< m
  Vec3 pointOnSecond;        ///< m
  Real distance = 0;         ///< m, |pointOnFirst − pointOnSecond|
};

/// Closest points of segments (p0, p1) and (q0, q1); robust for parallel and zero-length
/// segments (see the design note for which pair is returned when it is not unique).
SegmentClosestPoints closestPointsOnSegments(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                             const Vec3& q1);

/// The closest points of a segment and a triangle.
struct SegmentTriangleClosestPoints {
  Real segmentParameter = 0;  ///< s in [0, 1]: pointOnSegment = (1 − s)·p0 + s·p1
  Vec3 barycentric;           ///< weights of the triangle's corners a, b, c, each in [0, 1]
  Vec3 pointOnSegment;        ///< m
  Vec3 pointOnTriangle;       ///< m
  Real distance = 0;          ///< m, 0 when the segment crosses the triangle
};

/// Closest points of segment (p0, p1) and triangle (a, b, c). A zero-length segment is a point.
SegmentTriangleClosestPoints closestPointsOnSegmentAndTriangle(const Vec3& p0, const Vec3& p1,
                                                               const Vec3& a, const Vec3& b,
                                                               const Vec3& c);

}  // namespace weft
