// Capsule: the points within a radius of a segment along the body's y axis.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

namespace weft {

/// A solid capsule: radius around the body-frame segment from (0, −halfLength, 0) to
/// (0, +halfLength, 0). halfLength = 0 gives a sphere.
class Capsule {
 public:
  /// A capsule of `radius` (m, > 0) around a segment of length 2 · `halfLength` (m, ≥ 0).
  /// Errors: non-positive radius, negative half length, non-finite values, invalid motion.
  static Result<Capsule> create(Real radius, Real halfLength, const RigidMotion& motion = {});

  /// m, the radius.
  Real radius() const { return m_radius; }
  /// m, half the length of the core segment.
  Real halfLength() const { return m_halfLength; }
  /// Current pose and velocities.
  const RigidMotion& motion() const { return m_motion; }
  /// Moves the capsule (validated like create()); unchanged on error.
  Status setMotion(const RigidMotion& motion);
  /// Signed distance, closest point, normal and surface velocity for a world point. On the
  /// core segment itself the normal is the body's +x axis.
  ShapeContact queryPoint(const Vec3& point) const;
  /// World box.
  Aabb bounds() const;

 private:
  Real m_radius = 1;
  Real m_halfLength = 0;
  RigidMotion m_motion;
};

}  // namespace weft
