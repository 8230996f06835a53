// Plane: an infinite flat collider; the half-space behind it is solid (a floor, a wall).
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

namespace weft {

/// The plane through the body origin with outward normal `localNormal` (body frame). Points on
/// the normal's side are outside (distance > 0); the other side is solid.
class Plane {
 public:
  /// A plane with outward normal `localNormal` (any non-zero length; normalised) through
  /// motion.pose.position. Errors: zero or non-finite normal, invalid motion.
  static Result<Plane> create(const Vec3& localNormal, const RigidMotion& motion = {});

  /// Unit outward normal in the body frame.
  const Vec3& localNormal() const { return m_localNormal; }
  /// Unit outward normal in the world frame.
  Vec3 normal() const { return m_motion.pose.directionToWorld(m_localNormal); }
  /// Current pose and velocities.
  const RigidMotion& motion() const { return m_motion; }
  /// Moves the plane (validated like create()); unchanged on error.
  Status setMotion(const RigidMotion& motion);
  /// Signed distance, closest point, normal and surface velocity for a world point.
  ShapeContact queryPoint(const Vec3& point) const;
  /// Box of the solid half-space: unbounded (±∞) except along an axis-aligned normal.
  Aabb bounds() const;

 private:
  Vec3 m_localNormal = Vec3::UnitY();
  RigidMotion m_motion;
};

}  // namespace weft
