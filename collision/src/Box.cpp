// Oriented box collider: clamp to the box outside, nearest face inside.
#include <weft/collision/Box.h>

#include "ShapeSupport.h"

#include <cmath>

namespace weft {

Result<Box> Box::create(const Vec3& halfExtents, const RigidMotion& motion) {
  if (!isFinite(halfExtents) || !(halfExtents.minCoeff() > 0)) {
    return Error{"Box: half extents " + detail::formatVec(halfExtents) +
                 " m; pass three positive, finite half extents"};
  }
  Box box;
  box.m_halfExtents = halfExtents;
  if (Status status = box.setMotion(motion); !status) return status.error();
  return box;
}

Status Box::setMotion(const RigidMotion& motion) {
  RigidMotion checked = motion;
  if (Status status = validateMotion(checked, "Box"); !status) return status;
  m_motion = checked;
  return Status::success();
}

ShapeContact Box::queryPoint(const Vec3& point) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  const Vec3 clamped = local.cwiseMax(-m_halfExtents).cwiseMin(m_halfExtents);
  if (clamped != local) {
    // Outside: the clamped point is the closest.
    const Vec3 offset = local - clamped;
    const Real distance = offset.norm();
    return detail::worldContact(m_motion, distance, offset / distance, clamped);
  }
  // Inside (or on the surface): the face with the least depth; ties to the lower axis.
  int axis = 0;
  Real depth = m_halfExtents[0] - std::abs(local[0]);
  for (int i = 1; i < 3; ++i) {
    const Real faceDepth = m_halfExtents[i] - std::abs(local[i]);
    if (faceDepth < depth) {
      depth = faceDepth;
      axis = i;
    }
  }
  const Real side = local[axis] < 0 ? -1.0 : 1.0;
  Vec3 surfacePoint = local;
  surfacePoint[axis] = side * m_halfExtents[axis];
  return detail::worldContact(m_motion, -depth, side * Vec3::Unit(axis), surfacePoint);
}

Aabb Box::bounds() const {
  const Vec3 reach = m_motion.pose.rotation.toRotationMatrix().cwiseAbs() * m_halfExtents;
  return {m_motion.pose.position - reach, m_motion.pose.position + reach};
}

}  // namespace weft
