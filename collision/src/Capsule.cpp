// Capsule collider: distance to the core segment minus the radius.
#include <weft/collision/Capsule.h>

#include "ShapeSupport.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace weft {

Result<Capsule> Capsule::create(Real radius, Real halfLength, const RigidMotion& motion) {
  if (!(radius > 0) || !std::isfinite(radius)) {
    std::ostringstream text;
    text << "Capsule: radius is " << radius << " m; pass a positive, finite radius";
    return Error{text.str()};
  }
  if (!(halfLength >= 0) || !std::isfinite(halfLength)) {
    std::ostringstream text;
    text << "Capsule: half length is " << halfLength
         << " m; pass a finite half length ≥ 0 (0 makes a sphere)";
    return Error{text.str()};
  }
  Capsule capsule;
  capsule.m_radius = radius;
  capsule.m_halfLength = halfLength;
  if (Status status = capsule.setMotion(motion); !status) return status.error();
  return capsule;
}

Status Capsule::setMotion(const RigidMotion& motion) {
  RigidMotion checked = motion;
  if (Status status = validateMotion(checked, "Capsule"); !status) return status;
  m_motion = checked;
  return Status::success();
}

ShapeContact Capsule::queryPoint(const Vec3& point) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  const Vec3 core(0, std::clamp(local.y(), -m_halfLength, m_halfLength), 0);
  const Vec3 offset = local - core;
  const Real coreDistance = offset.norm();
  const Vec3 normal = coreDistance > 0 ? Vec3(offset / coreDistance) : Vec3(Vec3::UnitX());
  return detail::worldContact(m_motion, coreDistance - m_radius, normal,
                              core + m_radius * normal);
}

Aabb Capsule::bounds() const {
  const Vec3 top = m_motion.pose.toWorld(Vec3(0, m_halfLength, 0));
  const Vec3 bottom = m_motion.pose.toWorld(Vec3(0, -m_halfLength, 0));
  Aabb box = Aabb::fromCorners(top, bottom);
  box.inflate(m_radius);
  return box;
}

}  // namespace weft
