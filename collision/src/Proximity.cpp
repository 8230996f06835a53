// Point–triangle and segment–segment closest points. See Proximity.h for the design note.
#include <weft/collision/Proximity.h>

#include "TriangleRegions.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

Real clamp01(Real x) { return std::clamp(x, Real(0), Real(1)); }

// Closest point on segment (a, b) to p; parameter along a → b.
Real closestParameterOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const Real lengthSquared = ab.squaredNorm();
  if (lengthSquared <= 0) return 0;
  return clamp01((p - a).dot(ab) / lengthSquared);
}

TriangleClosestPoint makeResult(const Vec3& point, Real wa, Real wb, Real wc, const Vec3& a,
                                const Vec3& b, const Vec3& c) {
  TriangleClosestPoint result;
  result.barycentric = Vec3(wa, wb, wc);
  result.point = wa * a + wb * b + wc * c;
  // Exact corners, so that a vertex contact reports the vertex itself.
  if (wa == 1) result.point = a;
  if (wb == 1) result.point = b;
  if (wc == 1) result.point = c;
  result.distance = (point - result.point).norm();
  return result;
}

// Degenerate triangle: the closest of the three edges.
TriangleClosestPoint closestPointOnDegenerateTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                                      const Vec3& c) {
  const Real sab = closestParameterOnSegment(p, a, b);
  const Real sbc = closestParameterOnSegment(p, b, c);
  const Real sca = closestParameterOnSegment(p, c, a);
  const TriangleClosestPoint onAB = makeResult(p, 1 - sab, sab, 0, a, b, c);
  const TriangleClosestPoint onBC = makeResult(p, 0, 1 - sbc, sbc, a, b, c);
  const TriangleClosestPoint onCA = makeResult(p, sca, 0, 1 - sca, a, b, c);
  TriangleClosestPoint best = onAB;
  if (onBC.distance < best.distance) best = onBC;
  if (onCA.distance < best.distance) best = onCA;
  return best;
}

}  // namespace

TriangleClosestPoint closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b,
                                            const Vec3& c) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  // |ab × ac|² against the longest edge⁴: below 1e-12 the triangle is a sliver whose face
  // region cannot be computed reliably.
  const Real areaSquared = ab.cross(ac).squaredNorm();
  const Real longestSquared = std::max({ab.squaredNorm(), ac.squaredNorm(), (c - b).squaredNorm()});
  if (!(areaSquared > 1e-12 * longestSquared * longestSquared)) {
    return closestPointOnDegenerateTriangle(p, a, b, c);
  }

  return detail::closestTriangleRegion(p, a, b, c, [&](Real wa, Real wb, Real wc) {
    return makeResult(p, wa, wb, wc, a, b, c);
  });
}

SegmentClosestPoints closestPointsOnSegments(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                             const Vec3& q1) {
  const Vec3 d1 = p1 - p0;
  const Vec3 d2 = q1 - q0;
  const Vec3 r = p0 - q0;
  const Real a = d1.squaredNorm();
  const Real e = d2.squaredNorm();
  const Real f = d2.dot(r);
  Real s = 0;
  Real u = 0;
  if (a <= 0 && e <= 0) {
    // Two points.
  } else if (a <= 0) {
    u = clamp01(f / e);
  } else if (e <= 0) {
    s = clamp01(-d1.dot(r) / a);
  } else {
    const Real b = d1.dot(d2);
    const Real c = d1.dot(r);
    const Real denominator = a * e - b * b;  // = |d1 × d2|², ≥ 0
    if (denominator > 1e-12 * a * e) {
      s = clamp01((b * f - c * e) / denominator);
    } else {
      // Parallel: s at the middle of the overlap of q's projection onto p's line, or at the
      // nearer end of p when they do not overlap.
      const Real sAtQ0 = -c / a;
      const Real sAtQ1 = (b - c) / a;
      const Real low = std::max(Real(0), std::min(sAtQ0, sAtQ1));
      const Real high = std::min(Real(1), std::max(sAtQ0, sAtQ1));
      if (low <= high) {
        s = 0.5 * (low + high);
      } else {
        s = std::max(sAtQ0, sAtQ1) < 0 ? 0 : 1;
      }
    }
    u = (b * s + f) / e;
    if (u < 0) {
      u = 0;
      s = clamp01(-c / a);
    } else if (u > 1) {
      u = 1;
      s = clamp01((b - c) / a);
    }
  }
  SegmentClosestPoints result;
  result.firstParameter = s;
  result.secondParameter = u;
  result.pointOnFirst = p0 + s * d1;
  result.pointOnSecond = q0 + u * d2;
  result.distance = (result.pointOnFirst - result.pointOnSecond).norm();
  return result;
}

SegmentTriangleClosestPoints closestPointsOnSegmentAndTriangle(const Vec3& p0, const Vec3& p1,
                                                               const Vec3& a, const Vec3& b,
                                                               const Vec3& c) {
  SegmentTriangleClosestPoints best;
  // Does the segment cross the triangle? Its ends on opposite sides of the plane (or one on it),
  // and the crossing point inside. A degenerate triangle has no plane: its edges answer below.
  const Vec3 normal = (b - a).cross(c - a);
  const Real scale =
      std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), (c - b).squaredNorm()});
  if (normal.squaredNorm() > 1e-12 * scale * scale) {
    const Real side0 = normal.dot(p0 - a), side1 = normal.dot(p1 - a);
    if ((side0 <= 0 && side1 >= 0) || (side0 >= 0 && side1 <= 0)) {
      if (side0 != side1) {
        const Real s = side0 / (side0 - side1);
        const Vec3 crossing = p0 + s * (p1 - p0);
        const TriangleClosestPoint onPlane = closestPointOnTriangle(crossing, a, b, c);
        // The crossing point lies in the plane, so it is inside the triangle exactly when its
        // closest point is itself (to round-off of the plane's distance).
        if (onPlane.distance <= 1e-12 * std::sqrt(scale)) {
          best.segmentParameter = s;
          best.barycentric = onPlane.barycentric;
          best.pointOnSegment = crossing;
          best.pointOnTriangle = onPlane.point;
          best.distance = 0;
          return best;
        }
      }
    }
  }
  best.distance = std::numeric_limits<Real>::infinity();
  for (int end = 0; end < 2; ++end) {
    const Vec3& p = end == 0 ? p0 : p1;
    const TriangleClosestPoint onTriangle = closestPointOnTriangle(p, a, b, c);
    if (onTriangle.distance < best.distance) {
      best.segmentParameter = Real(end);
      best.barycentric = onTriangle.barycentric;
      best.pointOnSegment = p;
      best.pointOnTriangle = onTriangle.point;
      best.distance = onTriangle.distance;
    }
  }
  const Vec3* corners[3] = {&a, &b, &c};
  for (int edge = 0; edge < 3; ++edge) {
    const int from = edge, to = (edge + 1) % 3;
    const SegmentClosestPoints pair = closestPointsOnSegments(p0, p1, *corners[from], *corners[to]);
    if (pair.distance < best.distance) {
      best.segmentParameter = pair.firstParameter;
      best.barycentric = Vec3::Zero();
      best.barycentric[from] = 1 - pair.secondParameter;
      best.barycentric[to] = pair.secondParameter;
      best.pointOnSegment = pair.pointOnFirst;
      best.pointOnTriangle = pair.pointOnSecond;
      best.distance = pair.distance;
    }
  }
  return best;
}

}  // namespace weft
