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

#include <cmath>
#include <optional>
#include <variant>

namespace weft {

/// Any collider.
using Shape = std::variant<Plane, Sphere, Capsule, Box, TriangleMeshShape>;

/// Signed distance, closest point, outward normal and surface velocity of `shape` at a world
/// point.
inline ShapeContact queryPoint(const Shape& shape, const Vec3& point) {
  return std::visit([&](const auto& s) { return s.queryPoint(point); }, shape);
}

/// queryPoint() for a point nearer the surface of `shape` than `maxDistance` (m, on either side);
/// none for a point at least that far from it. A mesh prunes its search to that distance, so a
/// point far from it is cheap; the analytic shapes compute the distance and compare.
inline std::optional<ShapeContact> queryPointWithin(const Shape& shape, const Vec3& point,
                                                    Real maxDistance) {
  if (const TriangleMeshShape* mesh = std::get_if<TriangleMeshShape>(&shape)) {
    return mesh->queryPointWithin(point, maxDistance);
  }
  const ShapeContact contact = queryPoint(shape, point);
  if (!(std::abs(contact.distance) < maxDistance)) return std::nullopt;
  return contact;
}

/// queryPoint() for a point whose signed distance from `shape` is below `maxDistance` (m): inside
/// the body or nearer than that; none for a point at least that far outside. A mesh prunes its
/// search to that distance, and searches further only for a point inside its box.
inline std::optional<ShapeContact> queryPointBelow(const Shape& shape, const Vec3& point,
                                                   Real maxDistance) {
  if (const TriangleMeshShape* mesh = std::get_if<TriangleMeshShape>(&shape)) {
    return mesh->queryPointBelow(point, maxDistance);
  }
  const ShapeContact contact = queryPoint(shape, point);
  if (!(contact.distance < maxDistance)) return std::nullopt;
  return contact;
}

/// True when `shape` is a two-sided shell (an open TriangleMeshShape), whose unsigned distance
/// does not change sign where a path goes through it.
inline bool isTwoSided(const Shape& shape) {
  const TriangleMeshShape* mesh = std::get_if<TriangleMeshShape>(&shape);
  return mesh && !mesh->isClosed();
}

/// For a two-sided shape (isTwoSided), the parameter s ∈ [0, 1] where the world segment
/// a → b first meets its surface; none when it misses it, and always none for other shapes.
inline std::optional<Real> shellCrossing(const Shape& shape, const Vec3& a, const Vec3& b) {
  const TriangleMeshShape* mesh = std::get_if<TriangleMeshShape>(&shape);
  if (!mesh || mesh->isClosed()) return std::nullopt;
  return mesh->firstCrossing(a, b);
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
