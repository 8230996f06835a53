// ColliderFrame: a collider as one substep sees it, and the path queries every contact stage
// shares.
//
// A substep gets its colliders as values: a copy of each shape posed at the end of the substep
// (a mesh's geometry is shared, so the copy is cheap), its motion at both ends and the friction
// against the cloth. Nothing in a substep writes the world's colliders.
//
// Paths are followed relative to the body: a vertex's start point is carried with the body from
// its start pose to its end pose, and the segment from there to the vertex's end is traced
// against the posed shape (sphere tracing on the exact distance the shapes return). A rotation
// within the substep is followed through the two poses; translation is linear in between.
#pragma once

#include <weft/Math.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/Shape.h>

#include <optional>

namespace weft {

/// One collider as a substep sees it.
struct ColliderFrame {
  Shape shape;        ///< posed at the end of the substep
  RigidMotion start;  ///< motion at the start of the substep
  RigidMotion end;    ///< motion at the end of the substep (the shape's pose)
  Real friction = 0.3;  ///< Coulomb coefficient of the collider (the pair takes the geometric mean)

  /// `point` at the substep start, carried with the body to its end pose.
  Vec3 carry(const Vec3& point) const { return end.pose.toWorld(start.pose.toLocal(point)); }
  /// True when the body does not move within the substep.
  bool still() const {
    return start.pose.position == end.pose.position &&
           start.pose.rotation.coeffs() == end.pose.rotation.coeffs();
  }
};

/// Where a collider's motion puts it `dt` seconds later (constant linear and angular velocity).
RigidMotion advanceMotion(const RigidMotion& motion, Real dt);

/// Where a path first comes near a shape.
struct PathContact {
  Real s = 0;         ///< parameter along the path, 0 at its start, 1 at its end
  Vec3 point;         ///< the point of the path there
  Vec3 normal;        ///< the shape's outward normal there
  Real distance = 0;  ///< m, the point's signed distance to the shape
};

/// The first point of the segment a → b (a already carried with the body) closer to the shape
/// than `thickness`, or, for a path that starts within the thickness, closer than half its start
/// distance (a vertex in resting contact may move in the shell but not through the surface).
/// None when the path stays clear or starts inside.
std::optional<PathContact> firstContact(const Shape& shape, const Vec3& a, const Vec3& b,
                                        Real thickness);

/// Where a vertex moving from `start` to `end` over the substep ends without passing through the
/// collider or ending within its thickness: the path relative to the body stops where it first
/// meets the surface and slides on without its inward part; what is still within the thickness
/// goes onto it along the normal. `sweptHit` says whether the path met the surface.
Vec3 keepOutside(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Real thickness,
                 bool* sweptHit = nullptr);

/// True when some point of `points` may lie within `margin` of the shape (boxes, and for a plane
/// its signed distance at the box's corners).
bool mayTouch(const Shape& shape, const Aabb& points, Real margin);

/// keepOutside() for a path already in the body's end frame (`start` carried, or the body still).
Vec3 keepOutsideFrom(const Shape& shape, const Vec3& start, const Vec3& end, Real thickness,
                     bool* sweptHit = nullptr);

/// Coulomb friction on a tangential motion (a velocity or a displacement) under a normal one of
/// magnitude `normal` ≥ 0: zero when |tangential| ≤ μ·normal (it sticks), else shorter by μ·normal.
Vec3 coulombFriction(const Vec3& tangential, Real normal, Real friction);

}  // namespace weft
