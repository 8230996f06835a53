// Swept vertex–triangle and edge–edge tests: coplanarity cubic, candidate times, proximity at
// each candidate. See weft/collision/ContinuousCollision.h for the design note.
#include <weft/collision/ContinuousCollision.h>

#include <weft/collision/Proximity.h>

#include "CoplanarityCubic.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace detail {

Real Cubic::magnitude() const { return std::abs(c0) + std::abs(c1) + std::abs(c2) + std::abs(c3); }

Cubic tripleProductCubic(const Vec3& u0, const Vec3& du, const Vec3& v0, const Vec3& dv,
                         const Vec3& w0, const Vec3& dw) {
  // U × V = C0 + t C1 + t² C2, then dotted with W = w0 + t dw.
  const Vec3 cross0 = u0.cross(v0);
  const Vec3 cross1 = u0.cross(dv) + du.cross(v0);
  const Vec3 cross2 = du.cross(dv);
  Cubic f;
  f.c0 = cross0.dot(w0);
  f.c1 = cross1.dot(w0) + cross0.dot(dw);
  f.c2 = cross2.dot(w0) + cross1.dot(dw);
  f.c3 = cross2.dot(dw);
  return f;
}

void CandidateTimes::add(Real t) {
  if (t >= 0 && t <= 1 && count < static_cast<int>(times.size())) times[count++] = t;
}

void CandidateTimes::sort() { std::sort(times.begin(), times.begin() + count); }

void addQuadraticRootsAndVertex(Real q0, Real q1, Real q2, CandidateTimes& candidates) {
  if (q2 == 0) {
    if (q1 != 0) candidates.add(-q0 / q1);
    return;
  }
  candidates.add(-q1 / (2 * q2));
  const Real discriminant = q1 * q1 - 4 * q2 * q0;
  if (discriminant < 0) return;
  // q = −(q1 + sign(q1) √disc) / 2; the roots are q / q2 and q0 / q (no subtraction of
  // nearly equal numbers).
  const Real q = -0.5 * (q1 + std::copysign(std::sqrt(discriminant), q1));
  if (q == 0) {
    candidates.add(0);  // q1 = 0 and q0 = 0: a double root at 0
    return;
  }
  candidates.add(q / q2);
  candidates.add(q0 / q);
}

namespace {

// A time at most 1e-13 before the sign change of f on the monotone piece [low, high] (fLow:
// f(low)), never after it: the reported time of a crossing.
//
// Newton's method, kept inside a bracket that it shrinks (a bisection step wherever Newton's would
// leave it), finds the root x; two points x ∓ d then prove the crossing between them, each
// farther from zero than the rounding of Horner's rule can carry a value (γ₆ Σ|cᵢ| on [0, 1],
// Higham, "Accuracy and Stability of Numerical Algorithms", §5.1), so that the exact cubic has
// the computed signs there and x − d lies before the crossing in exact arithmetic. Where the
// proof fails (a crossing so flat that rounding blurs it over more than 1e-13), bisection of
// [low, high] to a bracket of 1e-13 decides.
// Rejected: bisection alone, about 43 dependent halvings for every crossing, whose direction is
// as unpredictable as the root's binary digits; it was the largest cost of the swept tests in
// crumpled cloth.
Real crossingTime(const Cubic& f, Real low, Real high, Real fLow) {
  constexpr Real kBracket = 1e-13;
  constexpr Real kEpsilon = std::numeric_limits<Real>::epsilon();
  // γ₆ = 6u / (1 − 6u) with u = ε/2 is 3ε and a little; 4ε bounds it.
  const Real margin = 4 * kEpsilon * f.magnitude();
  const bool negativeOnLeft = fLow < 0;
  auto slopeAt = [&](Real t) { return (3 * f.c3 * t + 2 * f.c2) * t + f.c1; };
  // f computes with fLow's sign at `left`, with the other at `right`.
  Real left = low, right = high;
  Real x = 0.5 * (low + high);
  for (int iteration = 0; iteration < 64; ++iteration) {
    const Real value = f(x);
    if (value == 0) break;
    ((value < 0) == negativeOnLeft ? left : right) = x;
    const Real slope = slopeAt(x);
    Real next = slope != 0 ? x - value / slope : x;
    if (!(next > left && next < right)) next = 0.5 * (left + right);
    const bool settled = std::abs(next - x) <= 4 * kEpsilon || right - left <= kBracket;
    x = next;
    if (settled) break;
  }
  const Real slope = std::abs(slopeAt(x));
  if (slope > 0) {
    const Real reach = margin / slope + 4 * kEpsilon;
    const Real before = x - reach, after = x + reach;
    if (after - before <= kBracket && before > low && after < high) {
      const Real fBefore = f(before), fAfter = f(after);
      if (std::abs(fBefore) > margin && (fBefore < 0) == negativeOnLeft &&
          std::abs(fAfter) > margin && (fAfter < 0) != negativeOnLeft) {
        return before;
      }
    }
  }
  left = low, right = high;
  for (int step = 0; step < 64 && right - left > kBracket; ++step) {
    const Real middle = 0.5 * (left + right);
    const Real fMiddle = f(middle);
    if (fMiddle == 0) return middle;
    ((fMiddle < 0) == negativeOnLeft ? left : right) = middle;
  }
  return left;
}

}  // namespace

CandidateTimes cubicCandidateTimes(const Cubic& f, Real slack) {
  // On [0, 1] the cubic lies within the range of its Bernstein coefficients (it is their convex
  // combination): when they all stay beyond ±slack, it cannot come within the slack of zero.
  // Most pairs resting side by side end here, without the derivative's roots.
  const Real b0 = f.c0, b1 = f.c0 + f.c1 / 3, b2 = f.c0 + (2 * f.c1 + f.c2) / 3,
             b3 = f.c0 + f.c1 + f.c2 + f.c3;
  if (std::min({b0, b1, b2, b3}) > slack || std::max({b0, b1, b2, b3}) < -slack) return {};
  // Piece ends: 0, the roots (and vertex) of f′ = 3 c3 t² + 2 c2 t + c1 inside (0, 1), 1.
  CandidateTimes breaks;
  breaks.add(0);
  addQuadraticRootsAndVertex(f.c1, 2 * f.c2, 3 * f.c3, breaks);
  breaks.add(1);
  breaks.sort();

  CandidateTimes candidates;
  for (int piece = 0; piece + 1 < breaks.count; ++piece) {
    const Real low = breaks.times[piece];
    const Real high = breaks.times[piece + 1];
    const Real fLow = f(low);
    const Real fHigh = f(high);
    if (std::abs(fLow) <= slack) candidates.add(low);
    if ((fLow < 0 && fHigh > 0) || (fLow > 0 && fHigh < 0)) {
      candidates.add(crossingTime(f, low, high, fLow));
    }
  }
  if (std::abs(f(1)) <= slack) candidates.add(1);
  candidates.sort();
  return candidates;
}

}  // namespace detail

namespace {

using detail::CandidateTimes;
using detail::Cubic;

constexpr Real kRoundoff = std::numeric_limits<Real>::epsilon();

// A vector moving linearly over the step: value(t) = start + t · change.
struct Moving {
  Vec3 start;
  Vec3 change;
  Vec3 at(Real t) const { return start + t * change; }
  Real maxNorm() const { return std::max(start.norm(), (start + change).norm()); }
};

Moving operator-(const Moving& x, const Moving& y) { return {x.start - y.start, x.change - y.change}; }

// The coplanarity cubic f(t) = (U × V) · W of three moving vectors, how far from zero it may
// stay while they are within `tolerance` of coplanar (round-off included), and the size of the
// configuration (|U| + |V| + |W| at their longest) that impact normals are judged against.
struct Coplanarity {
  detail::Cubic f;
  Real slack;
  Real scale;
};

Coplanarity coplanarity(const Moving& u, const Moving& v, const Moving& w, Real tolerance) {
  const Real scaleU = u.maxNorm(), scaleV = v.maxNorm(), scaleW = w.maxNorm();
  return {detail::tripleProductCubic(u.start, u.change, v.start, v.change, w.start, w.change),
          tolerance * scaleU * scaleV + 32 * kRoundoff * scaleU * scaleV * scaleW,
          scaleU + scaleV + scaleW};
}

// Times at which point `point` crosses the line of edge (from, to) inside the plane of normal
// `normal`: roots of ((to − from) × (point − from)) · normal.
void addCollinearityTimes(const Moving& from, const Moving& to, const Moving& point,
                          const Vec3& normal, CandidateTimes& candidates) {
  const Moving edge = to - from;
  const Moving offset = point - from;
  const Real q0 = edge.start.cross(offset.start).dot(normal);
  const Real q1 = (edge.start.cross(offset.change) + edge.change.cross(offset.start)).dot(normal);
  const Real q2 = edge.change.cross(offset.change).dot(normal);
  detail::addQuadraticRootsAndVertex(q0, q1, q2, candidates);
}

// The best-conditioned unit normal among t = 0, 1/2, 1 of the moving vector `normalAt(t)`;
// zero when it vanishes at all three.
template <typename NormalAt>
Vec3 bestUnitNormal(NormalAt normalAt) {
  Vec3 best = Vec3::Zero();
  for (Real t : {0.0, 0.5, 1.0}) {
    const Vec3 n = normalAt(t);
    if (n.squaredNorm() > best.squaredNorm()) best = n;
  }
  return best.squaredNorm() > 0 ? Vec3(best.normalized()) : Vec3::Zero();
}

// Any unit vector perpendicular to `direction` (which need not be unit; zero gives e_z): the
// cross product with the coordinate axis least aligned with it.
Vec3 anyPerpendicular(const Vec3& direction) {
  if (direction.squaredNorm() == 0) return Vec3::UnitZ();
  Vec3::Index axis = 0;
  direction.cwiseAbs().minCoeff(&axis);
  return direction.cross(Vec3::Unit(axis)).normalized();
}

// Sine of the angle between two vectors (0 when either vanishes).
Real sineBetween(const Vec3& x, const Vec3& y) {
  const Real lengths = x.norm() * y.norm();
  return lengths > 0 ? x.cross(y).norm() / lengths : 0;
}

// Orients `normal` so the first primitive approaches along −normal: relative velocity · normal
// ≤ 0; when they move tangentially, so the first primitive starts on the normal's side.
Vec3 orientTowardFirst(Vec3 normal, const Vec3& relativeVelocity, const Vec3& separationAtStart,
                       Real velocityScale) {
  const Real approach = relativeVelocity.dot(normal);
  if (approach > 1e-12 * velocityScale) return -normal;
  if (approach < -1e-12 * velocityScale) return normal;
  return separationAtStart.dot(normal) < 0 ? Vec3(-normal) : normal;
}

}  // namespace

std::optional<VertexTriangleImpact> sweptVertexTriangle(const Vec3& vertexStart,
                                                        const Vec3& vertexEnd,
                                                        const std::array<Vec3, 3>& triangleStart,
                                                        const std::array<Vec3, 3>& triangleEnd,
                                                        Real tolerance) {
  // Everything relative to corner a: U = b − a, V = c − a, W = p − a.
  const Moving a{triangleStart[0], triangleEnd[0] - triangleStart[0]};
  const Moving b{triangleStart[1], triangleEnd[1] - triangleStart[1]};
  const Moving c{triangleStart[2], triangleEnd[2] - triangleStart[2]};
  const Moving p{vertexStart, vertexEnd - vertexStart};
  const Moving u = b - a;
  const Moving v = c - a;
  const Moving w = p - a;
  const auto [f, slack, scale] = coplanarity(u, v, w, tolerance);

  CandidateTimes candidates;
  if (f.magnitude() > slack) {
    candidates = detail::cubicCandidateTimes(f, slack);
  } else {
    // Coplanar for the whole step: the vertex can only enter the triangle across an edge line.
    candidates.add(0);
    candidates.add(1);
    const Vec3 normal = bestUnitNormal([&](Real t) { return Vec3(u.at(t).cross(v.at(t))); });
    if (normal.squaredNorm() > 0) {
      const Moving origin{Vec3::Zero(), Vec3::Zero()};
      addCollinearityTimes(origin, u, w, normal, candidates);
      addCollinearityTimes(u, v, w, normal, candidates);
      addCollinearityTimes(v, origin, w, normal, candidates);
    }
    candidates.sort();
  }

  for (int i = 0; i < candidates.count; ++i) {
    const Real t = candidates.times[i];
    const Vec3 ut = u.at(t), vt = v.at(t), wt = w.at(t);
    const TriangleClosestPoint closest = closestPointOnTriangle(wt, Vec3::Zero(), ut, vt);
    if (!(closest.distance <= tolerance)) continue;

    VertexTriangleImpact impact;
    impact.time = t;
    impact.barycentric = closest.barycentric;
    impact.distance = closest.distance;
    Vec3 normal = ut.cross(vt);
    if (normal.squaredNorm() > 0) {
      normal.normalize();
    } else if (closest.distance > 0) {
      normal = (wt - closest.point) / closest.distance;
    } else {
      normal = anyPerpendicular(ut.squaredNorm() > 0 ? ut : vt);
    }
    const Real wb = closest.barycentric[1], wc = closest.barycentric[2];
    const Vec3 relativeVelocity = w.change - (wb * u.change + wc * v.change);
    const Vec3 separationAtStart = w.start - (wb * u.start + wc * v.start);
    impact.normal = orientTowardFirst(normal, relativeVelocity, separationAtStart,
                                      scale);
    return impact;
  }
  return std::nullopt;
}

std::optional<EdgeEdgeImpact> sweptEdgeEdge(const std::array<Vec3, 2>& firstStart,
                                            const std::array<Vec3, 2>& firstEnd,
                                            const std::array<Vec3, 2>& secondStart,
                                            const std::array<Vec3, 2>& secondEnd,
                                            Real tolerance) {
  // Everything relative to p0: U = p1 − p0, V = q1 − q0, W = q0 − p0.
  const Moving p0{firstStart[0], firstEnd[0] - firstStart[0]};
  const Moving p1{firstStart[1], firstEnd[1] - firstStart[1]};
  const Moving q0{secondStart[0], secondEnd[0] - secondStart[0]};
  const Moving q1{secondStart[1], secondEnd[1] - secondStart[1]};
  const Moving u = p1 - p0;
  const Moving v = q1 - q0;
  const Moving w = q0 - p0;
  const Moving wv{w.start + v.start, w.change + v.change};  // q1 − p0
  const auto [f, slack, scale] = coplanarity(u, v, w, tolerance);

  CandidateTimes candidates;
  if (f.magnitude() > slack) {
    candidates = detail::cubicCandidateTimes(f, slack);
  } else {
    // Coplanar or parallel for the whole step.
    candidates.add(0);
    candidates.add(1);
    const Moving origin{Vec3::Zero(), Vec3::Zero()};
    Vec3 normal = bestUnitNormal([&](Real t) { return Vec3(u.at(t).cross(v.at(t))); });
    // Below a sine of 1e-6 (0.2 arc seconds) the cross product of the edges is mostly rounding.
    const Real sine = std::max(sineBetween(u.at(0), v.at(0)), sineBetween(u.at(1), v.at(1)));
    if (sine < 1e-6) {
      // (Nearly) parallel: the plane through both lines, and the time the lines come closest.
      Vec3 direction = u.at(0.5);
      if (direction.squaredNorm() == 0) direction = v.at(0.5);
      if (direction.squaredNorm() > 0) direction.normalize();
      // Offset between the edge midpoints, without its component along the edges (linear in t).
      const Vec3 midStart = w.start + 0.5 * (v.start - u.start);
      const Vec3 midChange = w.change + 0.5 * (v.change - u.change);
      const Vec3 perpendicularStart = midStart - midStart.dot(direction) * direction;
      const Vec3 perpendicularChange = midChange - midChange.dot(direction) * direction;
      if (perpendicularChange.squaredNorm() > 0) {
        candidates.add(std::clamp(-perpendicularStart.dot(perpendicularChange) /
                                      perpendicularChange.squaredNorm(),
                                  Real(0), Real(1)));
      }
      normal = bestUnitNormal([&](Real t) {
        return Vec3(direction.cross(perpendicularStart + t * perpendicularChange));
      });
      if (normal.squaredNorm() == 0) normal = anyPerpendicular(direction);
    }
    if (normal.squaredNorm() > 0) {
      addCollinearityTimes(origin, u, w, normal, candidates);   // q0 against the first edge
      addCollinearityTimes(origin, u, wv, normal, candidates);  // q1 against the first edge
      addCollinearityTimes(w, wv, origin, normal, candidates);  // p0 against the second edge
      addCollinearityTimes(w, wv, u, normal, candidates);       // p1 against the second edge
    }
    candidates.sort();
  }

  for (int i = 0; i < candidates.count; ++i) {
    const Real t = candidates.times[i];
    const Vec3 ut = u.at(t), vt = v.at(t), wt = w.at(t);
    const SegmentClosestPoints closest = closestPointsOnSegments(Vec3::Zero(), ut, wt, wt + vt);
    if (!(closest.distance <= tolerance)) continue;

    EdgeEdgeImpact impact;
    impact.time = t;
    impact.firstParameter = closest.firstParameter;
    impact.secondParameter = closest.secondParameter;
    impact.distance = closest.distance;
    const Vec3 cross = ut.cross(vt);
    Vec3 normal;
    if (cross.squaredNorm() > 1e-12 * ut.squaredNorm() * vt.squaredNorm() &&
        cross.squaredNorm() > 0) {
      normal = cross.normalized();
    } else if (closest.distance > 0) {
      normal = (closest.pointOnFirst - closest.pointOnSecond) / closest.distance;
    } else {
      // Parallel and touching: perpendicular to the edge, toward where the first edge started.
      const Vec3 direction = ut.squaredNorm() > 0 ? ut : vt;
      const Vec3 separation = -(w.start + closest.secondParameter * v.start) +
                              closest.firstParameter * u.start;
      const Vec3 perpendicular =
          direction.squaredNorm() > 0
              ? Vec3(separation - separation.dot(direction) / direction.squaredNorm() * direction)
              : separation;
      normal = perpendicular.squaredNorm() > 0 ? Vec3(perpendicular.normalized())
                                               : anyPerpendicular(direction);
    }
    const Real s = closest.firstParameter, r = closest.secondParameter;
    const Vec3 relativeVelocity = s * u.change - (w.change + r * v.change);
    const Vec3 separationAtStart = s * u.start - (w.start + r * v.start);
    impact.normal = orientTowardFirst(normal, relativeVelocity, separationAtStart,
                                      scale);
    return impact;
  }
  return std::nullopt;
}

}  // namespace weft
