// Small helpers shared by the shape implementations (messages, contact assembly).
#pragma once

#include <weft/Math.h>
#include <weft/collision/RigidMotion.h>
#include <weft/collision/ShapeContact.h>

#include <sstream>
#include <string>

namespace weft::detail {

/// "(x, y, z)" for error messages.
inline std::string formatVec(const Vec3& v) {
  std::ostringstream text;
  text << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return text.str();
}

/// A contact computed in the body frame, moved to the world frame with the surface velocity.
inline ShapeContact worldContact(const RigidMotion& motion, Real distance, const Vec3& localNormal,
                                 const Vec3& localPoint) {
  ShapeContact contact;
  contact.distance = distance;
  contact.normal = motion.pose.directionToWorld(localNormal);
  contact.point = motion.pose.toWorld(localPoint);
  contact.velocity = motion.velocityAt(contact.point);
  return contact;
}

}  // namespace weft::detail
