// Segment–triangle and triangle–triangle intersection from exact orientation signs. See
// TriangleIntersection.h for the design note.
#include <weft/collision/TriangleIntersection.h>

#include <weft/collision/Proximity.h>

#include "Predicates.h"

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

using detail::orient2d;
using detail::orient3d;

Vec2 dropAxis(const Vec3& x, int axis) {
  switch (axis) {
    case 0: return Vec2(x.y(), x.z());
    case 1: return Vec2(x.z(), x.x());
    default: return Vec2(x.x(), x.y());
  }
}

// Closed 2D segments pq and rs share a point.
bool segmentsIntersect2d(const Vec2& p, const Vec2& q, const Vec2& r, const Vec2& s) {
  const int o1 = orient2d(p, q, r);
  const int o2 = orient2d(p, q, s);
  const int o3 = orient2d(r, s, p);
  const int o4 = orient2d(r, s, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;  // proper crossing
  // A point on the other segment's line and within its box (coordinates are exact: no rounding).
  auto onSegment = [](const Vec2& a, const Vec2& b, const Vec2& x) {
    return std::min(a.x(), b.x()) <= x.x() && x.x() <= std::max(a.x(), b.x()) &&
           std::min(a.y(), b.y()) <= x.y() && x.y() <= std::max(a.y(), b.y());
  };
  if (o1 == 0 && onSegment(p, q, r)) return true;
  if (o2 == 0 && onSegment(p, q, s)) return true;
  if (o3 == 0 && onSegment(r, s, p)) return true;
  if (o4 == 0 && onSegment(r, s, q)) return true;
  return false;
}

// Closed 2D point x in the closed, non-degenerate triangle abc.
bool pointInTriangle2d(const Vec2& x, const Vec2& a, const Vec2& b, const Vec2& c) {
  const int s1 = orient2d(a, b, x);
  const int s2 = orient2d(b, c, x);
  const int s3 = orient2d(c, a, x);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

// Segment and triangle known to lie in one plane.
bool coplanarSegmentIntersectsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                                       const Vec3& c) {
  // Project along the dominant normal axis; try the others if the projection is degenerate
  // (it can only be degenerate in every projection when the triangle itself is).
  const Vec3 normal = (b - a).cross(c - a).cwiseAbs();
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int i, int j) { return normal[i] > normal[j]; });
  for (int axis : order) {
    const Vec2 a2 = dropAxis(a, axis), b2 = dropAxis(b, axis), c2 = dropAxis(c, axis);
    if (orient2d(a2, b2, c2) == 0) continue;
    const Vec2 p2 = dropAxis(p, axis), q2 = dropAxis(q, axis);
    return pointInTriangle2d(p2, a2, b2, c2) || pointInTriangle2d(q2, a2, b2, c2) ||
           segmentsIntersect2d(p2, q2, a2, b2) || segmentsIntersect2d(p2, q2, b2, c2) ||
           segmentsIntersect2d(p2, q2, c2, a2);
  }
  // Degenerate triangle: the union of its edges (not exact, see the header).
  return closestPointsOnSegments(p, q, a, b).distance == 0 ||
         closestPointsOnSegments(p, q, b, c).distance == 0 ||
         closestPointsOnSegments(p, q, c, a).distance == 0;
}

// The segment's ends have orientations sp, sq (not both zero, not strictly the same side).
bool crossingSegmentIntersectsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                                       const Vec3& c) {
  const int s1 = orient3d(p, q, a, b);
  const int s2 = orient3d(p, q, b, c);
  const int s3 = orient3d(p, q, c, a);
  return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

bool segmentIntersectsTriangleWithSigns(const Vec3& p, const Vec3& q, int sp, int sq,
                                        const Vec3& a, const Vec3& b, const Vec3& c) {
  if (sp * sq > 0) return false;
  if (sp == 0 && sq == 0) return coplanarSegmentIntersectsTriangle(p, q, a, b, c);
  return crossingSegmentIntersectsTriangle(p, q, a, b, c);
}

}  // namespace

bool segmentIntersectsTriangle(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b,
                               const Vec3& c) {
  return segmentIntersectsTriangleWithSigns(p, q, orient3d(a, b, c, p), orient3d(a, b, c, q), a,
                                            b, c);
}

bool trianglesIntersect(const Vec3& a0, const Vec3& a1, const Vec3& a2, const Vec3& b0,
                        const Vec3& b1, const Vec3& b2) {
  // Sides of each triangle's vertices with respect to the other's plane: a strict separation
  // ends the test early (the common case for broad-phase candidates).
  const int sb0 = orient3d(a0, a1, a2, b0);
  const int sb1 = orient3d(a0, a1, a2, b1);
  const int sb2 = orient3d(a0, a1, a2, b2);
  if ((sb0 > 0 && sb1 > 0 && sb2 > 0) || (sb0 < 0 && sb1 < 0 && sb2 < 0)) return false;
  const int sa0 = orient3d(b0, b1, b2, a0);
  const int sa1 = orient3d(b0, b1, b2, a1);
  const int sa2 = orient3d(b0, b1, b2, a2);
  if ((sa0 > 0 && sa1 > 0 && sa2 > 0) || (sa0 < 0 && sa1 < 0 && sa2 < 0)) return false;

  return segmentIntersectsTriangleWithSigns(a0, a1, sa0, sa1, b0, b1, b2) ||
         segmentIntersectsTriangleWithSigns(a1, a2, sa1, sa2, b0, b1, b2) ||
         segmentIntersectsTriangleWithSigns(a2, a0, sa2, sa0, b0, b1, b2) ||
         segmentIntersectsTriangleWithSigns(b0, b1, sb0, sb1, a0, a1, a2) ||
         segmentIntersectsTriangleWithSigns(b1, b2, sb1, sb2, a0, a1, a2) ||
         segmentIntersectsTriangleWithSigns(b2, b0, sb2, sb0, a0, a1, a2);
}

}  // namespace weft
