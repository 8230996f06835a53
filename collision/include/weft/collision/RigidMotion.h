// Pose and velocity of a rigid, kinematic collider.
//
// Colliders are kinematic: a script (or the game) sets their pose every frame and says how fast
// they move; the cloth does not push them. The velocities are what the contact response needs to
// compute relative velocity and friction (surface velocity = v + ω × (x − position)).
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>

#include <Eigen/Geometry>

#include <string_view>

namespace weft {

/// Unit quaternion in double precision.
using Quat = Eigen::Quaternion<Real>;

/// Position and orientation of a body: world = rotation · local + position.
struct Pose {
  Vec3 position = Vec3::Zero();    ///< m, origin of the body frame in world coordinates
  Quat rotation = Quat::Identity(); ///< body frame → world frame; must be a unit quaternion

  /// Body-frame point → world.
  Vec3 toWorld(const Vec3& local) const { return rotation * local + position; }
  /// World point → body frame.
  Vec3 toLocal(const Vec3& world) const { return rotation.conjugate() * (world - position); }
  /// Body-frame direction → world (no translation).
  Vec3 directionToWorld(const Vec3& local) const { return rotation * local; }
  /// World direction → body frame (no translation).
  Vec3 directionToLocal(const Vec3& world) const { return rotation.conjugate() * world; }
};

/// Pose plus the velocities of a kinematic body.
struct RigidMotion {
  Pose pose;                                ///< where the body is now
  Vec3 linearVelocity = Vec3::Zero();       ///< m/s, velocity of pose.position
  Vec3 angularVelocity = Vec3::Zero();      ///< rad/s, world frame, about pose.position

  /// m/s, velocity of the body's material point at `worldPoint`: v + ω × (x − position).
  Vec3 velocityAt(const Vec3& worldPoint) const {
    return linearVelocity + angularVelocity.cross(worldPoint - pose.position);
  }
};

/// Checks a motion for use by a shape named `owner` (in the messages): finite position and
/// velocities, and a rotation quaternion of norm 1 within 1e-6. On success the rotation is
/// renormalised exactly in `motion`.
Status validateMotion(RigidMotion& motion, std::string_view owner);

}  // namespace weft
