#include "contact/ColliderFrame.h"

#include <algorithm>
#include <limits>
#include <variant>

namespace weft {

RigidMotion advanceMotion(const RigidMotion& motion, Real dt) {
  RigidMotion moved = motion;
  moved.pose.position += dt * motion.linearVelocity;
  const Real angle = motion.angularVelocity.norm() * dt;
  if (angle > 0) {
    const Quat turn(Eigen::AngleAxis<Real>(angle, motion.angularVelocity.normalized()));
    moved.pose.rotation = (turn * motion.pose.rotation).normalized();
  }
  return moved;
}

namespace {

// Sphere tracing of the path `pointAt(s)`, s ∈ [0, 1], from a to b, whose speed |d point / ds|
// is at most `speed` (firstContact()'s rules). Sphere tracing never steps over the level set:
// the shapes return exact distances and no point of the path moves faster than `speed`. A path
// in the shell steps at least a quarter thickness at a time, so a vertex sliding on a surface
// does not crawl; that minimum can cut a dip shorter than a quarter thickness, never a body
// thicker than that. A path not through after the step budget stops where it got (early, not
// through).
template <class PointAt>
std::optional<PathContact> trace(const Shape& shape, const PointAt& pointAt, Real speed,
                                 const Vec3& a, const Vec3& b, Real thickness) {
  // A start farther from the surface than the path is long plus the thickness stays clear: the
  // bounded query lets a mesh prune its search to that distance.
  const std::optional<ShapeContact> start = queryPointWithin(shape, a, speed + thickness);
  if (!start) return std::nullopt;  // far outside, or deep inside
  const Real startDistance = start->distance;
  if (!(startDistance > 0)) return std::nullopt;  // starts inside: only a projection can help
  const Real level = startDistance >= thickness ? thickness : 0.5 * startDistance;
  if (!(speed > 0)) return std::nullopt;
  constexpr int kMaxSteps = 256;
  const Real minimumStep = 0.25 * thickness;
  // A two-sided shell (an open mesh) has no beyond with a negative distance: a minimum step
  // longer than the distance allows is tested for a crossing, and a path that crosses stops at
  // the sample before it, on its own side.
  const bool twoSided = isTwoSided(shape);
  Real s = 0;
  for (int step = 0; step < kMaxSteps; ++step) {
    const Vec3 point = s == 0 ? a : pointAt(s);
    // A point farther from the surface than the rest of the path is long plus the thickness:
    // the path stays clear (this bound lets a mesh prune its search).
    const std::optional<ShapeContact> near =
        step == 0 ? start : queryPointWithin(shape, point, speed * (1 - s) + thickness);
    if (!near) return std::nullopt;
    const ShapeContact& contact = *near;
    if (contact.distance < level || step + 1 == kMaxSteps) {
      return PathContact{s, point, contact.normal, contact.distance, contact.normal};
    }
    const Real safeStep = contact.distance - 0.5 * level;
    if (twoSided && safeStep < minimumStep &&
        shellCrossing(shape, point, pointAt(std::min<Real>(1, s + minimumStep / speed)))) {
      return PathContact{s, point, contact.normal, contact.distance, contact.normal};
    }
    s += std::max(safeStep, minimumStep) / speed;
    if (s > 1) {
      const std::optional<ShapeContact> end = queryPointBelow(shape, b, level);
      if (end) return PathContact{1, b, end->normal, end->distance, end->normal};
      return std::nullopt;
    }
  }
  return std::nullopt;
}

// From a hit the vertex keeps its motion relative to the body but the part into the surface
// (inelastic): it slides on. Carrying it with the body instead would glue a vertex that brushed
// a collider to it. The slide is traced again (a concave or curved body) in the end pose; after
// a few slides that still hit, it stays at the last hit point, which is outside. Then what is
// within the thickness goes onto it: the path there is clear, so the nearest face is the one it
// came to.
Vec3 slideOn(const Shape& shape, std::optional<PathContact> hit, const Vec3& end, Real thickness) {
  Vec3 x = end;
  constexpr int kSlides = 3;
  for (int slide = 0; hit; ++slide) {
    if (slide == kSlides) {
      x = hit->point;
      break;
    }
    Vec3 remaining = x - hit->point;
    const Real inward = remaining.dot(hit->normal);
    if (inward < 0) remaining -= inward * hit->normal;
    x = hit->point + remaining;
    hit = firstContact(shape, hit->point, x, thickness);
  }
  if (const std::optional<ShapeContact> contact = queryPointBelow(shape, x, thickness)) {
    x += (thickness - contact->distance) * contact->normal;
  }
  return x;
}

}  // namespace

Pose ColliderFrame::poseAt(Real s) const {
  Pose pose;
  pose.position = (1 - s) * start.pose.position + s * end.pose.position;
  pose.rotation = start.pose.rotation.slerp(s, end.pose.rotation);
  return pose;
}

Real ColliderFrame::turn() const {
  if (start.pose.rotation.coeffs() == end.pose.rotation.coeffs()) return 0;
  return Eigen::AngleAxis<Real>(end.pose.rotation * start.pose.rotation.conjugate()).angle();
}

Vec3 ColliderFrame::turnVector() const {
  if (start.pose.rotation.coeffs() == end.pose.rotation.coeffs()) return Vec3::Zero();
  const Eigen::AngleAxis<Real> turn(end.pose.rotation * start.pose.rotation.conjugate());
  return turn.angle() * turn.axis();
}

namespace {

// firstContact() along the path relative to a turning body of a vertex moving on a straight line
// from `from` at time s0 of the substep (a fraction) to `to` at its end. The point relative to
// the body, u(s) = x(s) − c(s), is linear in s; turned by the body it moves at most θ |u| + |u'|
// per unit of s, and |u| is largest at an end.
std::optional<PathContact> traceTurning(const ColliderFrame& collider, const Vec3& from, Real s0,
                                        const Vec3& to, Real thickness) {
  if (!(s0 < 1)) return std::nullopt;
  const Pose startPose = collider.poseAt(s0);
  const Vec3 u0 = from - startPose.position;
  const Vec3 u1 = to - collider.end.pose.position;
  const Real speed = (1 - s0) * collider.turn() * std::max(u0.norm(), u1.norm()) + (u1 - u0).norm();
  const Vec3 travel = to - from;
  const Vec3 a = collider.end.pose.toWorld(startPose.toLocal(from));
  std::optional<PathContact> hit = trace(
      collider.shape,
      [&](Real s) -> Vec3 {
        return s >= 1 ? to : collider.carryFrom(from + s * travel, s0 + s * (1 - s0));
      },
      speed, a, to, thickness);
  if (hit) {
    // The end pose's normal, turned back to the instant of the hit.
    const Pose then = collider.poseAt(s0 + hit->s * (1 - s0));
    hit->impactNormal =
        then.directionToWorld(collider.end.pose.directionToLocal(hit->normal));
  }
  return hit;
}

}  // namespace

std::optional<PathContact> firstContact(const Shape& shape, const Vec3& a, const Vec3& b,
                                        Real thickness) {
  const Vec3 travel = b - a;
  return trace(shape, [&](Real s) -> Vec3 { return a + s * travel; }, travel.norm(), a, b,
               thickness);
}

std::optional<PathContact> firstContactAlong(const ColliderFrame& collider, const Vec3& start,
                                             const Vec3& end, Real thickness) {
  if (collider.turn() == 0) {
    return firstContact(collider.shape, collider.carry(start), end, thickness);
  }
  return traceTurning(collider, start, 0, end, thickness);
}

Real pathBulge(const ColliderFrame& collider, const Vec3& start, const Vec3& end) {
  const Real turn = collider.turn();
  if (turn == 0) return 0;
  // A curve strays from its chord by at most max |q''| / 8; q'' = Θ×(Θ×u) − 2 Θ×u'.
  const Vec3 u0 = start - collider.start.pose.position;
  const Vec3 u1 = end - collider.end.pose.position;
  return 0.125 * (turn * turn * std::max(u0.norm(), u1.norm()) + 2 * turn * (u1 - u0).norm());
}

void addRelativePath(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Aabb& box,
                     Real& bulge) {
  box.expand(collider.carry(start));
  box.expand(end);
  bulge = std::max(bulge, pathBulge(collider, start, end));
}

Vec3 keepOutside(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Real thickness,
                 bool* sweptHit) {
  if (collider.turn() == 0) {
    // The path relative to the body is a segment; sliding on it is sliding in the world.
    const std::optional<PathContact> hit =
        firstContact(collider.shape, collider.carry(start), end, thickness);
    if (sweptHit) *sweptHit = hit.has_value();
    return slideOn(collider.shape, hit, end, thickness);
  }
  // A turning body: the vertex moves on straight pieces in the world, from `from` at time s0 of
  // the substep to x at its end; at a hit the inward part of its velocity relative to the body
  // is removed along the normal of that instant, and it goes on from the hit.
  const Vec3 turnVector = collider.turnVector();
  const Vec3 bodyTravel = collider.end.pose.position - collider.start.pose.position;
  Vec3 from = start, x = end;
  Real s0 = 0;
  std::optional<PathContact> hit = traceTurning(collider, from, s0, x, thickness);
  if (sweptHit) *sweptHit = hit.has_value();
  constexpr int kSlides = 3;
  for (int slide = 0; hit; ++slide) {
    if (slide == kSlides) {
      x = hit->point;  // outside the body at its end pose
      break;
    }
    const Real s = s0 + hit->s * (1 - s0);
    const Vec3 point = from + hit->s * (x - from);
    // Per unit of s: the vertex's travel and the body's at the point.
    const Vec3 relative = (x - from) / (1 - s0) -
                          (bodyTravel + turnVector.cross(point - collider.poseAt(s).position));
    const Real inward = relative.dot(hit->impactNormal);
    if (inward < 0) x -= ((1 - s) * inward) * hit->impactNormal;
    if (!(s < 1)) break;
    from = point;
    s0 = s;
    hit = traceTurning(collider, from, s0, x, thickness);
  }
  if (const std::optional<ShapeContact> contact = queryPointBelow(collider.shape, x, thickness)) {
    x += (thickness - contact->distance) * contact->normal;
  }
  return x;
}

Vec3 keepOutsideFrom(const Shape& shape, const Vec3& start, const Vec3& end, Real thickness,
                     bool* sweptHit) {
  std::optional<PathContact> hit = firstContact(shape, start, end, thickness);
  if (sweptHit) *sweptHit = hit.has_value();
  return slideOn(shape, hit, end, thickness);
}

bool mayTouch(const Shape& shape, const Aabb& points, Real margin) {
  if (points.isEmpty()) return false;
  Aabb box = bounds(shape);
  box.inflate(margin);
  if (!box.overlaps(points)) return false;
  if (const Plane* plane = std::get_if<Plane>(&shape)) {
    // A tilted half-space has an unbounded box; its signed distance is linear, so the corners of
    // the points' box bound it from below.
    Real nearest = std::numeric_limits<Real>::infinity();
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 point((corner & 1) ? points.max.x() : points.min.x(),
                       (corner & 2) ? points.max.y() : points.min.y(),
                       (corner & 4) ? points.max.z() : points.min.z());
      nearest = std::min(nearest, plane->queryPoint(point).distance);
    }
    return nearest < margin;
  }
  return true;
}

Vec3 coulombFriction(const Vec3& tangential, Real normal, Real friction) {
  const Real length = tangential.norm();
  if (!(length > 0)) return tangential;
  const Real kept = std::max<Real>(0, 1 - friction * normal / length);
  return tangential * kept;
}

}  // namespace weft
