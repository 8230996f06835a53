// Exact orientation predicates for doubles: the sign of orient2d and orient3d, always right.
//
// Design note
// -----------
// The triangle–triangle test decides intersection from signs of orientation determinants. With
// plain double arithmetic those signs are wrong near degeneracy (a vertex within rounding of
// the other triangle's plane), and different tests of the same configuration can then disagree
// with each other, which is how "robust" tests end up both missing intersections and finding
// phantom ones. Here the sign is exact for any finite double input (barring overflow and
// underflow):
//
// * Filter. The determinant is evaluated in double with Shewchuk's a-priori error bound
//   (Shewchuk 1997, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//   Predicates", the bounds ccwerrboundA and o3derrboundA). Outside the bound the double sign is
//   certain, which is the answer for all but near-degenerate inputs.
// * Exact fallback. Otherwise the determinant is recomputed as a floating-point expansion (a sum
//   of non-overlapping doubles, Shewchuk §2): exact differences (two-sum), exact products
//   (two-product with std::fma), exact sums (grow-expansion). The sign of an expansion is the
//   sign of its largest component. This is the plain, unoptimised form of Shewchuk's method —
//   no adaptive stages B and C — because it runs only on the rare inputs the filter rejects.
//   Rejected: long double or __float128 (still inexact, just less often), GMP rationals (an
//   extra dependency for a rare path).
#pragma once

#include <weft/Math.h>

namespace weft::detail {

/// Sign (−1, 0, +1) of det[a − c; b − c] over the (x, y) plane: +1 when a, b, c turn
/// counter-clockwise. Exact.
int orient2d(const Vec2& a, const Vec2& b, const Vec2& c);

/// Sign (−1, 0, +1) of (a − d) · ((b − d) × (c − d)): +1 when d lies on the side of plane abc
/// opposite to the normal (b − a) × (c − a), i.e. abc turns clockwise seen from d. Exact.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

}  // namespace weft::detail
