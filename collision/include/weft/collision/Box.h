// Box: an oriented box (its axes are the body frame's axes).
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

namespace weft {

/// A solid box centred at the body origin, extending ±halfExtents along the body axes.
class Box {
 public:
  /// A box of `halfExtents` (m, each > 0). Errors: non-positive or non-finite half extent,
  /// invalid motion.
  static Result<Box> create(const Vec3& halfExtents, const RigidMotion& motion = {});

  /// m, half the edge lengths along the body axes.
  const Vec3& halfExtents() const { return m_halfExtents; }
  /// Current pose and velocities.
  const RigidMotion& motion() const { return m_motion; }
  /// Moves the box (validated like create()); unchanged on error.
  Status setMotion(const RigidMotion& motion);
  /// Signed distance, closest point, normal and surface velocity for a world point. Inside, the
  /// nearest face wins (ties go to the lower axis, x before y before z).
  ShapeContact queryPoint(const Vec3& point) const;
  /// World box of the rotated box.
  Aabb bounds() const;

 private:
  Vec3 m_halfExtents = Vec3::Ones();
  RigidMotion m_motion;
};

}  // namespace weft
