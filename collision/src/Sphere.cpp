// Sphere collider.
#include <weft/collision/Sphere.h>

#include "ShapeSupport.h"

#include <cmath>
#include <sstream>

namespace weft {

Result<Sphere> Sphere::create(Real radius, const RigidMotion& motion) {
  if (!(radius > 0) || !std::isfinite(radius)) {
    std::ostringstream text;
    text << "Sphere: radius is " << radius << " m; pass a positive, finite radius";
    return Error{text.str()};
  }
  Sphere sphere;
  sphere.m_radius = radius;
  if (Status status = sphere.setMotion(motion); !status) return status.error();
  return sphere;
}

Status Sphere::setMotion(const RigidMotion& motion) {
  RigidMotion checked = motion;
  if (Status status = validateMotion(checked, "Sphere"); !status) return status;
  m_motion = checked;
  return Status::success();
}

ShapeContact Sphere::queryPoint(const Vec3& point) const {
  const Vec3 local = m_motion.pose.toLocal(point);
  const Real centerDistance = local.norm();
  const Vec3 normal = centerDistance > 0 ? Vec3(local / centerDistance) : Vec3(Vec3::UnitY());
  return detail::worldContact(m_motion, centerDistance - m_radius, normal, m_radius * normal);
}

Aabb Sphere::bounds() const {
  return {center().array() - m_radius, center().array() + m_radius};
}

}  // namespace weft
