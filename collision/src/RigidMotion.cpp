// Validation of kinematic motions.
#include <weft/collision/RigidMotion.h>

#include "ShapeSupport.h"

#include <cmath>
#include <sstream>

namespace weft {

Status validateMotion(RigidMotion& motion, std::string_view owner) {
  if (!isFinite(motion.pose.position)) {
    return Error{std::string(owner) + ": pose position " + detail::formatVec(motion.pose.position) +
                 " is not finite; pass a finite position in metres"};
  }
  const Eigen::Vector4d coefficients = motion.pose.rotation.coeffs();
  if (!coefficients.allFinite()) {
    return Error{std::string(owner) +
                 ": pose rotation has a non-finite component; pass a unit quaternion"};
  }
  const Real norm = coefficients.norm();
  if (!(std::abs(norm - 1) <= 1e-6)) {
    std::ostringstream text;
    text << owner << ": pose rotation has norm " << norm
         << "; pass a unit quaternion (call normalized() on it)";
    return Error{text.str()};
  }
  if (!isFinite(motion.linearVelocity)) {
    return Error{std::string(owner) + ": linear velocity " +
                 detail::formatVec(motion.linearVelocity) + " is not finite; pass m/s"};
  }
  if (!isFinite(motion.angularVelocity)) {
    return Error{std::string(owner) + ": angular velocity " +
                 detail::formatVec(motion.angularVelocity) + " is not finite; pass rad/s"};
  }
  motion.pose.rotation.normalize();
  return Status::success();
}

}  // namespace weft
