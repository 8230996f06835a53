// The Voronoi-region walk of a point against a triangle (Ericson 2005, "Real-Time Collision
// Detection", §5.1.5), shared by closestPointOnTriangle and the mesh collider's cheaper
// squared-distance search, so both find the same region by the same arithmetic.
#pragma once

#include <weft/Math.h>

namespace weft::detail {

/// Finds the region of triangle (a, b, c) (not a sliver: see closestPointOnTriangle) holding
/// the point closest to p and returns region(wa, wb, wc) with its barycentric weights (exact 0
/// and 1 on edges and corners).
template <class Region>
auto closestTriangleRegion(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                           Region region) {
  const Vec3 ab = b - a;
  const Vec3 ac = c - a;
  // Vertex region a.
  const Vec3 ap = p - a;
  const Real d1 = ab.dot(ap);
  const Real d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return region(Real(1), Real(0), Real(0));
  // Vertex region b.
  const Vec3 bp = p - b;
  const Real d3 = ab.dot(bp);
  const Real d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return region(Real(0), Real(1), Real(0));
  // Edge region ab.
  const Real vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const Real s = d1 / (d1 - d3);
    return region(1 - s, s, Real(0));
  }
  // Vertex region c.
  const Vec3 cp = p - c;
  const Real d5 = ab.dot(cp);
  const Real d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return region(Real(0), Real(0), Real(1));
  // Edge region ac.
  const Real vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const Real s = d2 / (d2 - d6);
    return region(1 - s, Real(0), s);
  }
  // Edge region bc.
  const Real va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const Real s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return region(Real(0), 1 - s, s);
  }
  // Face region: va, vb, vc are the (scaled) barycentric weights.
  const Real inverse = 1 / (va + vb + vc);
  const Real wb = vb * inverse;
  const Real wc = vc * inverse;
  return region(1 - wb - wc, wb, wc);
}

}  // namespace weft::detail
