// Sphere: a ball of given radius centred at the body origin.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

namespace weft {

/// A solid ball centred at motion.pose.position.
class Sphere {
 public:
  /// A sphere of `radius` (m, > 0). Errors: non-positive or non-finite radius, invalid motion.
  static Result<Sphere> create(Real radius, const RigidMotion& motion = {});

  /// m, the radius.
  Real radius() const { return m_radius; }
  /// m, the centre in world coordinates.
  const Vec3& center() const { return m_motion.pose.position; }
  /// Current pose and velocities.
  const RigidMotion& motion() const { return m_motion; }
  /// Moves the sphere (validated like create()); unchanged on error.
  Status setMotion(const RigidMotion& motion);
  /// Signed distance, closest point, normal and surface velocity for a world point. At the exact
  /// centre the normal is the body's +y axis.
  ShapeContact queryPoint(const Vec3& point) const;
  /// World box.
  Aabb bounds() const;

 private:
  Real m_radius = 1;
  RigidMotion m_motion;
};

}  // namespace weft
