// Plane collider: signed distance to the plane through the body origin.
#include <weft/collision/Plane.h>

#include "ShapeSupport.h"

#include <limits>

namespace weft {

Result<Plane> Plane::create(const Vec3& localNormal, const RigidMotion& motion) {
  if (!isFinite(localNormal) || localNormal.squaredNorm() == 0) {
    return Error{"Plane: normal " + detail::formatVec(localNormal) +
                 " cannot be normalised; pass a finite, non-zero outward normal"};
  }
  Plane plane;
  plane.m_localNormal = localNormal.normalized();
  if (Status status = plane.setMotion(motion); !status) return status.error();
  return plane;
}

Status Plane::setMotion(const RigidMotion& motion) {
  RigidMotion checked = motion;
  if (Status status = validateMotion(checked, "Plane"); !status) return status;
  m_motion = checked;
  return Status::success();
}

ShapeContact Plane::queryPoint(const Vec3& point) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  const Real distance = local.dot(m_localNormal);
  return detail::worldContact(m_motion, distance, m_localNormal, local - distance * m_localNormal);
}

Aabb Plane::bounds() const {
  constexpr Real kInfinity = std::numeric_limits<Real>::infinity();
  Aabb box{Vec3::Constant(-kInfinity), Vec3::Constant(kInfinity)};
  const Vec3 normal = this->normal();
  for (int axis = 0; axis < 3; ++axis) {
    // Only an exactly axis-aligned normal bounds the solid side along that axis.
    const Vec3 axisDirection = Vec3::Unit(axis);
    if (normal == axisDirection) box.max[axis] = m_motion.pose.position[axis];
    if (normal == -axisDirection) box.min[axis] = m_motion.pose.position[axis];
  }
  return box;
}

}  // namespace weft
