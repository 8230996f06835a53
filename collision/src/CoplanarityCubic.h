// The root finder behind the continuous tests: candidate coplanarity times of four linearly
// moving points. Internal; tested alone in tests/collision/ContinuousCollisionTest.cpp. The
// method and its tolerances are explained in weft/collision/ContinuousCollision.h.
#pragma once

#include <weft/Math.h>

#include <array>

namespace weft::detail {

/// f(t) = c3 t³ + c2 t² + c1 t + c0.
struct Cubic {
  Real c0 = 0;  ///< constant coefficient
  Real c1 = 0;  ///< linear coefficient
  Real c2 = 0;  ///< quadratic coefficient
  Real c3 = 0;  ///< cubic coefficient
  /// f(t) by Horner's rule.
  Real operator()(Real t) const { return ((c3 * t + c2) * t + c1) * t + c0; }
  /// |c0| + |c1| + |c2| + |c3|: a bound on |f| over [0, 1].
  Real magnitude() const;
};

/// The coefficients of (U(t) × V(t)) · W(t) for U(t) = u0 + t du (and likewise V, W).
Cubic tripleProductCubic(const Vec3& u0, const Vec3& du, const Vec3& v0, const Vec3& dv,
                         const Vec3& w0, const Vec3& dw);

/// Up to 12 times in [0, 1], ascending.
struct CandidateTimes {
  std::array<Real, 12> times{};  ///< the candidates, ascending, in [0, 1]
  int count = 0;                 ///< how many of `times` are used
  /// Appends t if it lies in [0, 1] and there is room (sort() orders them).
  void add(Real t);
  /// Sorts the candidates ascending.
  void sort();
};

/// Roots in [0, 1] of q2 t² + q1 t + q0 (cancellation-free; linear when q2 = 0; nothing when
/// the polynomial is identically zero), plus the vertex −q1 / (2 q2) when it lies in [0, 1], so
/// that a tangency missed by rounding (discriminant slightly negative) is still a candidate.
void addQuadraticRootsAndVertex(Real q0, Real q1, Real q2, CandidateTimes& candidates);

/// Candidate times of f = 0 on [0, 1]: every sign change (a time at most 1e-13 before it, never
/// after) and every piece end with |f| ≤ slack, where the pieces are [0, 1] cut at the roots of
/// f′. Ascending.
CandidateTimes cubicCandidateTimes(const Cubic& f, Real slack);

}  // namespace weft::detail
