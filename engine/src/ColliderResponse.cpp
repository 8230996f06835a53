#include "ColliderResponse.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>

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

Index ColliderResponse::constrain(std::span<const ColliderFrame> colliders, const Vec3Array& x,
                                  const Vec3Array& v, Real h, Real thickness,
                                  const std::vector<char>& pinned, VertexFilter& filter) {
  release(filter);
  if (colliders.empty()) return 0;
  WEFT_PROFILE_ZONE("narrow phase");
  for (Index i = 0; i < x.size(); ++i) {
    if (pinned[i]) continue;
    const Vec3 predicted = x[i] + h * v[i];
    // The deepest contact wins when a vertex touches several colliders: one direction per vertex
    // keeps the filter simple; the after-step pass still separates it from the others.
    Real deepest = thickness;
    Vec3 normal = Vec3::Zero();
    for (const ColliderFrame& collider : colliders) {
      const ShapeContact contact = queryPoint(*collider.shape, predicted);
      if (contact.distance < deepest) {
        deepest = contact.distance;
        normal = contact.normal;
      }
    }
    if (normal.isZero()) continue;
    // n·Δv that ends the step exactly at the thickness: d(x + h(v + Δv)) ≈ d(x + h v) + h n·Δv.
    filter.setConstrained(i, normal, normal * ((thickness - deepest) / h));
    m_constrained.push_back(i);
  }
  return Index(m_constrained.size());
}

void ColliderResponse::release(VertexFilter& filter) {
  for (Index vertex : m_constrained) filter.setFree(vertex);
  m_constrained.clear();
}

namespace {

// Earliest parameter s ∈ [0, 1] at which the segment a → b comes within `thickness` of the
// shape, by sphere tracing: the shapes return exact Euclidean distances, so stepping by the
// distance minus the thickness never steps over the surface. −1 when the segment stays clear.
Real sweptContact(const Shape& shape, const Vec3& a, const Vec3& b, Real thickness) {
  const Vec3 travel = b - a;
  const Real length = travel.norm();
  Real s = 0;
  // 64 steps: each one halves the remaining distance or better near a surface; a segment that
  // needs more is grazing, and the projection at the end handles a graze.
  for (int step = 0; step < 64; ++step) {
    const Real distance = queryPoint(shape, a + s * travel).distance;
    if (distance < thickness) return s;
    if (length == 0) return -1;
    s += (distance - 0.5 * thickness) / length;
    if (s > 1) return -1;
  }
  return -1;
}

}  // namespace

ColliderResponseReport ColliderResponse::resolve(std::span<const ColliderFrame> colliders,
                                                 const Vec3Array& xStart, const Vec3Array& vStart,
                                                 Real thickness,
                                                 const std::vector<char>& pinned, Vec3Array& x,
                                                 Vec3Array& v) const {
  ColliderResponseReport report;
  report.constrainedVertices = Index(m_constrained.size());
  if (colliders.empty()) return report;
  WEFT_PROFILE_ZONE("response");
  for (Index i = 0; i < x.size(); ++i) {
    if (pinned[i]) continue;
    bool touched = false;
    for (const ColliderFrame& collider : colliders) {
      const Shape& shape = *collider.shape;
      ShapeContact contact = queryPoint(shape, x[i]);
      if (contact.distance >= thickness) {
        // Outside at the end: did the vertex pass through the collider on the way? Follow its
        // motion relative to the body: its start point, carried with the body to the end pose.
        const Vec3 carriedStart =
            collider.end.pose.toWorld(collider.start.pose.toLocal(xStart[i]));
        if (queryPoint(shape, carriedStart).distance < thickness) continue;  // started in contact: projection handles it
        const Real s = sweptContact(shape, carriedStart, x[i], thickness);
        if (s < 0) continue;
        // The vertex met the surface at s. For the rest of the step it keeps its motion relative
        // to the body except the part into the surface (inelastic): it slides on. Carrying it
        // with the body instead would glue a vertex that merely brushed a collider to it, and a
        // collider sliding past the cloth would drag it along.
        const Vec3 relativeTravel = x[i] - carriedStart;
        const Vec3 hit = carriedStart + s * relativeTravel;
        const Vec3 hitNormal = queryPoint(shape, hit).normal;
        Vec3 remaining = (1 - s) * relativeTravel;
        const Real inward = remaining.dot(hitNormal);
        if (inward < 0) remaining -= inward * hitNormal;
        x[i] = hit + remaining;
        contact = queryPoint(shape, x[i]);
        ++report.sweptHits;
      }
      // Onto the surface plus thickness (a vertex that slid clear of it stays where it is).
      if (contact.distance < thickness) x[i] += (thickness - contact.distance) * contact.normal;
      // Inelastic: no relative velocity into the surface.
      const Vec3 relative = v[i] - contact.velocity;
      const Real normalSpeed = relative.dot(contact.normal);
      Vec3 normalPart = normalSpeed * contact.normal;
      Vec3 tangential = relative - normalPart;
      if (normalSpeed < 0) normalPart.setZero();
      // Coulomb friction: the normal velocity change over the step (from the solve's constraint
      // and from this pass) bounds how much tangential velocity friction may remove.
      const Real normalChange =
          std::max<Real>(0, (v[i] - vStart[i]).dot(contact.normal)) + std::max<Real>(0, -normalSpeed);
      const Real tangentialSpeed = tangential.norm();
      if (tangentialSpeed > 0) {
        const Real kept = std::max<Real>(0, 1 - collider.friction * normalChange / tangentialSpeed);
        tangential *= kept;
      }
      v[i] = contact.velocity + normalPart + tangential;
      touched = true;
    }
    report.contacts += touched ? 1 : 0;
  }
  return report;
}

}  // namespace weft
