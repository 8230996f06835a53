// Aabb: an axis-aligned bounding box, the one bounding volume of the collision module.
//
// Boxes are closed: two boxes that only touch overlap, so a vertex lying exactly on a face still
// produces a candidate pair. The empty box has min = +∞ and max = −∞, which makes expand() a
// plain cwiseMin / cwiseMax with no special case.
#pragma once

#include <weft/Math.h>

#include <limits>

namespace weft {

/// An axis-aligned box [min, max] (closed). Default-constructed boxes are empty.
struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<Real>::infinity());   ///< m, lower corner
  Vec3 max = Vec3::Constant(-std::numeric_limits<Real>::infinity());  ///< m, upper corner

  /// The empty box (contains nothing; expand() from here gives the bounds of what is added).
  static Aabb empty() { return {}; }
  /// The box spanned by two corners given in any order.
  static Aabb fromCorners(const Vec3& a, const Vec3& b) { return {a.cwiseMin(b), a.cwiseMax(b)}; }

  /// True when the box contains no point (min > max on some axis).
  bool isEmpty() const { return (min.array() > max.array()).any(); }
  /// Grows the box to contain `point`.
  void expand(const Vec3& point) {
    min = min.cwiseMin(point);
    max = max.cwiseMax(point);
  }
  /// Grows the box to contain `other`.
  void expand(const Aabb& other) {
    min = min.cwiseMin(other.min);
    max = max.cwiseMax(other.max);
  }
  /// Moves every face outward by `margin` (m); an empty box stays empty.
  void inflate(Real margin) {
    min.array() -= margin;
    max.array() += margin;
  }
  /// True when the closed boxes share at least one point.
  bool overlaps(const Aabb& other) const {
    // Short-circuit &&: most box pairs of the self query fail the first test, so it is faster
    // there than a branch-free `&` of all six.
    return min.x() <= other.max.x() && other.min.x() <= max.x() &&  //
           min.y() <= other.max.y() && other.min.y() <= max.y() &&  //
           min.z() <= other.max.z() && other.min.z() <= max.z();
  }
  /// True when `point` lies in the closed box.
  bool contains(const Vec3& point) const {
    return (point.array() >= min.array()).all() && (point.array() <= max.array()).all();
  }
  /// m, the centre (meaningless for an empty or unbounded box).
  Vec3 center() const { return 0.5 * (min + max); }
  /// m, the edge lengths max − min.
  Vec3 extent() const { return max - min; }
  /// m², half the surface area (xy + yz + zx); a cheap size measure for traversal decisions.
  Real halfSurfaceArea() const {
    const Vec3 e = extent();
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
  /// m², squared distance from `point` to the box (0 inside).
  Real squaredDistanceTo(const Vec3& point) const {
    const Vec3 below = (min - point).cwiseMax(0.0);
    const Vec3 above = (point - max).cwiseMax(0.0);
    return (below + above).squaredNorm();
  }

  /// Same corners, bit for bit.
  friend bool operator==(const Aabb& a, const Aabb& b) { return a.min == b.min && a.max == b.max; }
};

}  // namespace weft
