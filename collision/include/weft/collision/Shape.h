// Shape: any collider, as a value (std::variant), with the queries every shape answers.
//
// A closed set of shapes in a variant rather than a virtual base class: colliders are values
// the world can store in one vector without a heap allocation per shape, copy for rollback, and
// dispatch with one switch. Adding a shape means adding it here and to the visitors below.
#pragma once

#include <weft/collision/Box.h>
#include <weft/collision/Capsule.h>
#include <weft/collision/Plane.h>
#include <weft/collision/Sphere.h>
#include <weft/collision/TriangleMeshShape.h>

#include <variant>

namespace weft {

/// Any collider.
using Shape = std::variant<Plane, Sphere, Capsule, Box, TriangleMeshShape>;

/// Signed distance, closest point, outward normal and surface velocity of `shape` at a world
/// point.
inline ShapeContact queryPoint(const Shape& shape, const Vec3& point) {
  return std::visit([&](const auto& s) { return s.queryPoint(point); }, shape);
}

/// World box of `shape` (possibly unbounded for a plane).
inline Aabb bounds(const Shape& shape) {
  return std::visit([](const auto& s) { return s.bounds(); }, shape);
}

/// Current pose and velocities of `shape`.
inline const RigidMotion& motion(const Shape& shape) {
  return std::visit([](const auto& s) -> const RigidMotion& { return s.motion(); }, shape);
}

/// Moves `shape` (validated; unchanged on error).
inline Status setMotion(Shape& shape, const RigidMotion& newMotion) {
  return std::visit([&](auto& s) { return s.setMotion(newMotion); }, shape);
}

}  // namespace weft
