// ColliderFrame: a collider as one substep sees it, and the path queries every contact stage
// shares.
//
// A substep gets its colliders as values: a copy of each shape posed at the end of the substep
// (a mesh's geometry is shared, so the copy is cheap), its motion at both ends and the friction
// against the cloth. Nothing in a substep writes the world's colliders.
//
// Paths are followed relative to the body: the vertex moves on its segment x₀ → x₁ while the
// body moves with constant velocities (positions interpolate linearly, rotations spherically),
// and each point of the segment is carried from the body's pose at that instant to its end pose,
// where the shape is posed; that curve is sphere traced on the exact distance the shapes return.
// A body that only translates makes it the segment from the carried start to x₁. A rotating one
// makes it an arc: a vertex at rest in the world beside a spinning body keeps its distance along
// it. The chord from the carried start instead cuts into a curved body by ρθ²/8 (ρ the distance
// from the axis, θ the turn in the substep), and a trace that stops there pushes the vertex out
// along the normal where the body was, so a frictionless contact would take the body's turn.
#pragma once

#include <weft/Math.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/Shape.h>

#include <optional>

namespace weft {

/// Vertices per parallel block of per-vertex collider queries: an analytic shape costs ~50 ns a
/// vertex, a triangle mesh ~1 µs, so a block is 6–130 µs of work, above a fork/join.
inline constexpr Index kGrainVertexQueries = 128;

/// One collider as a substep sees it.
struct ColliderFrame {
  Shape shape;        ///< posed at the end of the substep
  RigidMotion start;  ///< motion at the start of the substep
  RigidMotion end;    ///< motion at the end of the substep (the shape's pose)
  Real friction = 0.3;  ///< Coulomb coefficient of the collider (the pair takes the geometric mean)

  /// `point` at the substep start, carried with the body to its end pose.
  Vec3 carry(const Vec3& point) const { return end.pose.toWorld(start.pose.toLocal(point)); }
  /// The body's pose at fraction s ∈ [0, 1] of the substep.
  Pose poseAt(Real s) const;
  /// `point` at fraction s of the substep, carried with the body to its end pose.
  Vec3 carryFrom(const Vec3& point, Real s) const {
    return end.pose.toWorld(poseAt(s).toLocal(point));
  }
  /// rad, the angle the body turns through within the substep.
  Real turn() const;
  /// rad, the body's turn over the substep as a rotation vector (world axis times angle).
  Vec3 turnVector() const;
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
  /// The outward normal at the instant of the hit, in the world then: the direction a
  /// frictionless contact pushes. `normal` (the end pose's) unless the body turns.
  Vec3 impactNormal;
};

/// The first point of the segment a → b (a already carried with the body) closer to the shape
/// than `thickness`, or, for a path that starts within the thickness, closer than half its start
/// distance (a vertex in resting contact may move in the shell but not through the surface).
/// None when the path stays clear or starts inside.
std::optional<PathContact> firstContact(const Shape& shape, const Vec3& a, const Vec3& b,
                                        Real thickness);

/// firstContact() along the path relative to the body of a vertex moving from `start` to `end`
/// over the substep (see the file comment; the path starts at carry(start) and ends at `end`).
std::optional<PathContact> firstContactAlong(const ColliderFrame& collider, const Vec3& start,
                                             const Vec3& end, Real thickness);

/// m, how far the path relative to the body of a vertex moving from `start` to `end` may stray
/// from the box of carry(start) and `end` (zero for a body that does not turn).
Real pathBulge(const ColliderFrame& collider, const Vec3& start, const Vec3& end);

/// Adds to `box` the path relative to the body, in its end frame, of a point moving from `start`
/// to `end` (the start carried with the body, and the end), and raises `bulge` (m) to how far
/// that path, an arc for a turning body, strays from its chord: inflated by `bulge`, the box
/// holds every point of the path.
void addRelativePath(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Aabb& box,
                     Real& bulge);

/// Where a vertex moving from `start` to `end` over the substep ends without passing through the
/// collider or ending within its thickness: the path relative to the body stops where it first
/// meets the surface and slides on without the inward part of its velocity relative to the body
/// (the impulse is along the normal at the instant of the hit, so a frictionless contact keeps
/// its tangential motion in the world); what is still within the thickness goes onto it along
/// the normal. `sweptHit` says whether the path met the surface.
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
