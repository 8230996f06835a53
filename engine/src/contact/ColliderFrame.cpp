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

std::optional<PathContact> firstContact(const Shape& shape, const Vec3& a, const Vec3& b,
                                        Real thickness) {
  const Real startDistance = queryPoint(shape, a).distance;
  if (!(startDistance > 0)) return std::nullopt;  // starts inside: only a projection can help
  const Real level = startDistance >= thickness ? thickness : 0.5 * startDistance;
  const Vec3 travel = b - a;
  const Real length = travel.norm();
  if (length == 0) return std::nullopt;
  // Sphere tracing never steps over the level set: the shapes return exact distances. A path in
  // the shell steps at least a quarter thickness at a time, so a vertex sliding on a surface does
  // not crawl; that minimum can cut a dip shorter than a quarter thickness, never a body thicker
  // than that. A path not through after the step budget stops where it got (early, not through).
  constexpr int kMaxSteps = 256;
  const Real minimumStep = 0.25 * thickness;
  Real s = 0;
  for (int step = 0; step < kMaxSteps; ++step) {
    const Vec3 point = a + s * travel;
    const ShapeContact contact = queryPoint(shape, point);
    if (contact.distance < level || step + 1 == kMaxSteps) {
      return PathContact{s, point, contact.normal, contact.distance};
    }
    s += std::max(contact.distance - 0.5 * level, minimumStep) / length;
    if (s > 1) {
      const ShapeContact end = queryPoint(shape, b);
      if (end.distance < level) return PathContact{1, b, end.normal, end.distance};
      return std::nullopt;
    }
  }
  return std::nullopt;
}

Vec3 keepOutside(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Real thickness,
                 bool* sweptHit) {
  return keepOutsideFrom(collider.shape, collider.carry(start), end, thickness, sweptHit);
}

Vec3 keepOutsideFrom(const Shape& shape, const Vec3& start, const Vec3& end, Real thickness,
                     bool* sweptHit) {
  Vec3 x = end;
  std::optional<PathContact> hit = firstContact(shape, start, x, thickness);
  if (sweptHit) *sweptHit = hit.has_value();
  // From a hit the vertex keeps its motion relative to the body but the part into the surface
  // (inelastic): it slides on. Carrying it with the body instead would glue a vertex that brushed
  // a collider to it. The slide is traced again (a concave or curved body); after a few slides
  // that still hit, it stays at the last hit point, which is outside.
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
  // Onto the surface plus thickness: the path there is clear, so the nearest face is the one it
  // came to.
  const ShapeContact contact = queryPoint(shape, x);
  if (contact.distance < thickness) x += (thickness - contact.distance) * contact.normal;
  return x;
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
