// Continuous (swept) collision tests: vertex–triangle and edge–edge over one step, t ∈ [0, 1].
//
// Design note
// -----------
// What. Every point moves linearly over the step, x(t) = x_start + t (x_end − x_start). A vertex
// and a triangle (or two edges) can only pass through each other at a time when their four
// points are coplanar. Coplanarity is the cubic
//     f(t) = (U(t) × V(t)) · W(t) = c3 t³ + c2 t² + c1 t + c0,
// with U, V the triangle edges b − a, c − a and W = p − a (vertex–triangle), or U, V the two edge
// directions and W = q0 − p0 (edge–edge), all linear in t (Provot 1997; Bridson, Fedkiw &
// Anderson 2002, §4). At each coplanar time the primitives' true distance is computed with the
// closest-point kernels; the earliest coplanar time at which it is within `tolerance` is the
// time of contact. So the contract is: a contact is reported at the earliest t ∈ [0, 1] at which
// the four points are coplanar (within the slack below) and the primitives are within
// `tolerance` of each other. Contacts at t = 0 (already touching) are reported.
//
// Root finding. The coefficients are computed from vectors relative to one of the points (no
// cancellation from large absolute coordinates). [0, 1] is split at the real roots of f′ (a
// quadratic, solved with the cancellation-free formula; linear and constant f′ are handled), so f
// is monotone on every piece. On a piece, a sign change is bracketed and bisected to a width of
// 1e-13 (the left end of the final bracket is reported, so the time is never after the crossing);
// a piece end where |f| ≤ slack (a double root, a touch at t = 0 or t = 1) is a candidate too.
// Bisection rather than Newton: it cannot leave the bracket or stall at the flat double roots
// that touching contacts produce, and 45 steps of a Horner cubic cost nothing next to the
// broad phase. Rejected: the closed-form cubic solution (catastrophic cancellation near double
// roots, exactly the touching cases), and exact CCD (Brochu, Fedkiw & Bridson 2012; Tang et al.
// 2014), whose root parity counting is exact but gives no time of contact for the response.
//
// Slack. |f(t)| ≤ slack is treated as coplanar, with
//     slack = tolerance · |U|max · |V|max + 32 ε |U|max |V|max |W|max,
// where |·|max is the larger of the norms at t = 0 and t = 1. The first term is the largest |f|
// can be while the point is within `tolerance` of the plane (|f| = height · |U × V|), the
// second bounds the rounding of f. A slack that is too generous only costs proximity checks; it
// never creates a contact, because a contact also needs the true distance ≤ tolerance.
//
// Degenerate cases. When |c0| + |c1| + |c2| + |c3| ≤ slack, the points stay coplanar (or, for
// edges, parallel) for the whole step and f carries no information. Then the candidates are
// t = 0, t = 1 and the times at which a point crosses the line of an edge inside the common
// plane (quadratics in t, with the plane normal taken where it is best conditioned), plus, for
// edge–edge, the time of closest approach of the two (nearly parallel) lines. This handles
// motion inside the plane of the face and parallel edges sliding onto each other; it is a best
// effort when the common plane rotates during the step, where the edge–edge tests of the
// neighbouring edges are the backstop (as Bridson et al. note for coplanar motion).
//
// Tolerances. `tolerance` (default 1e-6 m) is the distance at a coplanar time that counts as
// contact: it must be far below the cloth thickness (3 mm) and above the rounding of positions
// (1e-16 · |x|). Time precision is 1e-13 of the step for a clean crossing. For grazing motion,
// whose normal speed is a fraction r of the tangential one, rounding in f moves the root by
// about ε / r (6e-6 of the step at r = 1e-8); the normal offset at the reported time stays
// ~ε · |x|, so the contact is still real (distance ≤ tolerance), only its time is blurred.
// The tests check the contract on random constructed crossings (sizes 1 mm to 1 m, far from the
// origin, r down to 1e-9), coplanar and parallel motions, and near misses beside an edge.
#pragma once

#include <weft/Math.h>

#include <array>
#include <optional>

namespace weft {

/// m, default distance at a coplanar time that counts as contact (see the design note).
inline constexpr Real kDefaultContactTolerance = 1e-6;

/// First contact of a moving vertex with a moving triangle.
struct VertexTriangleImpact {
  Real time = 0;      ///< fraction of the step in [0, 1] at first contact
  Vec3 barycentric;   ///< weights of the triangle corners at the contact point (sum 1)
  /// Unit triangle normal at `time`, pointing to the side the vertex comes from: the relative
  /// velocity (vertex − triangle point) · normal ≤ 0 unless they move tangentially.
  Vec3 normal;
  Real distance = 0;  ///< m, vertex–triangle distance at `time` (≤ tolerance)
};

/// First contact of two moving edges.
struct EdgeEdgeImpact {
  Real time = 0;             ///< fraction of the step in [0, 1] at first contact
  Real firstParameter = 0;   ///< s: contact point on the first edge = (1 − s) p0 + s p1
  Real secondParameter = 0;  ///< u: contact point on the second edge = (1 − u) q0 + u q1
  /// Unit normal at `time` (perpendicular to both edges unless they are parallel), pointing from
  /// the second edge to the side the first edge comes from.
  Vec3 normal;
  Real distance = 0;         ///< m, edge–edge distance at `time` (≤ tolerance)
};

/// Earliest contact of vertex p (moving vertexStart → vertexEnd) with triangle (a, b, c) (corners
/// moving triangleStart → triangleEnd), or nothing. All motion is linear over t ∈ [0, 1].
std::optional<VertexTriangleImpact> sweptVertexTriangle(
    const Vec3& vertexStart, const Vec3& vertexEnd, const std::array<Vec3, 3>& triangleStart,
    const std::array<Vec3, 3>& triangleEnd, Real tolerance = kDefaultContactTolerance);

/// Earliest contact of edge (p0, p1) with edge (q0, q1), both moving linearly from their start
/// to their end positions over t ∈ [0, 1], or nothing.
std::optional<EdgeEdgeImpact> sweptEdgeEdge(const std::array<Vec3, 2>& firstStart,
                                            const std::array<Vec3, 2>& firstEnd,
                                            const std::array<Vec3, 2>& secondStart,
                                            const std::array<Vec3, 2>& secondEnd,
                                            Real tolerance = kDefaultContactTolerance);

}  // namespace weft
