#include "ColliderResponse.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

// Two contact normals closer than this (cosine) are one surface for ContactHolds.
constexpr Real kSameNormal = 0.999;
// A vertex the solve pressed onto a collider is in contact up to this fraction of the thickness
// beyond it: the constraint is linear, and a vertex sliding over a curved body ends outside by
// about h² v_t² / 2R (5 µm, 0.15 % of 3 mm, for 0.1 m/s on a 30 cm sphere at 1/60 s).
constexpr Real kPressedShell = 0.01;

}  // namespace

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
    // A vertex resting at the thickness (to the pressed shell's margin) is constrained too, so
    // that every vertex of a cloth lying on a body takes its support from the solve; left to
    // round-off, some were and their neighbours were not, and the constrained ones carried
    // their neighbours' weight (5x their own on a sliding cloth) into friction's bound. A
    // constraint that would pull is released by the solve (ImplicitEuler).
    Real deepest = (1 + kPressedShell) * thickness;
    Vec3 normal = Vec3::Zero();
    for (const ColliderFrame& collider : colliders) {
      // The predicted motion relative to the body, from the start point carried with it: where
      // it first meets the body gives the face to stop on. The end pose alone would push a
      // vertex that a fast body overran out through the nearest face, the side or the far one.
      const Vec3 carriedStart = collider.end.pose.toWorld(collider.start.pose.toLocal(x[i]));
      Real depth;  // signed distance of the predicted point along the chosen normal
      Vec3 direction;
      const ShapeContact contact = queryPoint(*collider.shape, predicted);
      direction = contact.normal;
      depth = contact.distance;
      if (const std::optional<PathContact> hit =
              firstContact(*collider.shape, carriedStart, predicted, thickness)) {
        // A path that stays outside the body after it comes near (the end outside, on the side
        // it came to, and the middle from there clear too) is a graze: the end's own distance
        // holds. Extrapolating the hit's tangent plane instead overshoots on a curved body: a
        // sheet on top of a 15 cm sphere that pulls away sideways by 6.7 cm in a step ends
        // 1.7 cm clear of it, and the plane put it 0.5 mm inside, so the solve held it against
        // the sheet's tension with an impulse of 36 m/s, which friction then turned into drag.
        // A two-sided shell (an open mesh) has no inside to show the middle in: there the path
        // from the hit on is tested for a crossing instead.
        const bool graze = contact.distance > 0 && contact.normal.dot(hit->normal) > 0 &&
                           queryPoint(*collider.shape, 0.5 * (hit->point + predicted)).distance > 0 &&
                           !shellCrossing(*collider.shape, hit->point, predicted);
        if (!graze) {
          direction = hit->normal;
          depth = hit->distance + hit->normal.dot(predicted - hit->point);
        }
      }
      if (depth < deepest) {
        deepest = depth;
        normal = direction;
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

std::optional<PathContact> firstContact(const Shape& shape, const Vec3& a, const Vec3& b,
                                        Real thickness) {
  const Vec3 travel = b - a;
  const Real length = travel.norm();
  // A start farther from the surface than the path is long plus the thickness stays clear: the
  // bounded query lets a mesh prune its search to that distance.
  const std::optional<ShapeContact> start = queryPointWithin(shape, a, length + thickness);
  if (!start) return std::nullopt;  // far outside, or deep inside
  const Real startDistance = start->distance;
  if (!(startDistance > 0)) return std::nullopt;  // starts inside: only a projection can help
  // A path that starts within the thickness (a vertex in resting contact) is stopped where it
  // gets halfway from there to the surface: it may move about in the shell, never through it.
  const Real level = startDistance >= thickness ? thickness : 0.5 * startDistance;
  if (length == 0) return std::nullopt;
  // Sphere tracing: the shapes return exact Euclidean distances, so stepping by the distance
  // minus half the level never steps over the level set. A path that starts in the shell steps
  // at least a quarter of the thickness at a time: tracing it by its distance alone would crawl
  // along a surface it lies on (a tiny level, a tiny step), and then run out of steps and stop a
  // sliding vertex. That minimum can cut a dip below the level shorter than a quarter thickness,
  // never a crossing of a body thicker than that: a sample beyond the surface is found. A path
  // still not through after the step budget is stopped where it got (early rather than
  // through: the caller slides it on from there). A two-sided shell (an open mesh) has no
  // beyond with a negative distance: a minimum step longer than the distance allows is tested
  // for a crossing, and a path that crosses stops at the sample before it, on its side.
  constexpr int kMaxSteps = 256;
  const Real minimumStep = 0.25 * thickness;
  const bool twoSided = isTwoSided(shape);
  Real s = 0;
  for (int step = 0; step < kMaxSteps; ++step) {
    const Vec3 point = a + s * travel;
    const ShapeContact contact = step == 0 ? *start : queryPoint(shape, point);
    if (contact.distance < level || step + 1 == kMaxSteps) {
      return PathContact{s, point, contact.normal, contact.distance};
    }
    const Real safeStep = contact.distance - 0.5 * level;
    if (twoSided && safeStep < minimumStep &&
        shellCrossing(shape, point, a + std::min<Real>(1, s + minimumStep / length) * travel)) {
      return PathContact{s, point, contact.normal, contact.distance};
    }
    s += std::max(safeStep, minimumStep) / length;
    if (s > 1) {
      // The end itself, which the last step may have passed over.
      const ShapeContact end = queryPoint(shape, b);
      if (end.distance < level) return PathContact{1, b, end.normal, end.distance};
      return std::nullopt;
    }
  }
  return std::nullopt;
}

Vec3 keepOutside(const ColliderFrame& collider, const Vec3& start, const Vec3& end, Real thickness,
                 bool* sweptHit) {
  const Shape& shape = *collider.shape;
  // Follow the motion relative to the body: the start point, carried with the body to the end
  // pose.
  const Vec3 carriedStart = collider.end.pose.toWorld(collider.start.pose.toLocal(start));
  Vec3 x = end;
  std::optional<PathContact> hit = firstContact(shape, carriedStart, x, thickness);
  if (sweptHit) *sweptHit = hit.has_value();
  // From a hit the vertex keeps its motion relative to the body except the part into the
  // surface (inelastic): it slides on. Carrying it with the body instead would glue a vertex
  // that merely brushed a collider to it, and a collider sliding past the cloth would drag it
  // along. The slide is tested again (a concave body, or a curved one it slides into); after a
  // few slides that still hit, it stays at the last hit point, which is outside.
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
  // came to (a vertex that slid clear of the surface stays where it is).
  const ShapeContact contact = queryPoint(shape, x);
  if (contact.distance < thickness) x += (thickness - contact.distance) * contact.normal;
  return x;
}

Vec3 coulombFriction(const Vec3& tangential, Real normalImpulse, Real friction) {
  const Real speed = tangential.norm();
  if (!(speed > 0)) return tangential;
  // 1 − μ J / |v_t|, cut at 0: a contact within the cone keeps none of its tangential velocity.
  const Real kept = std::max<Real>(0, 1 - friction * normalImpulse / speed);
  return tangential * kept;
}

ColliderResponseReport ColliderResponse::resolve(std::span<const ColliderFrame> colliders,
                                                 const Vec3Array& xStart, const Vec3Array& vStart,
                                                 Real thickness,
                                                 const std::vector<char>& pinned, Vec3Array& x,
                                                 Vec3Array& v, ContactHolds* holds,
                                                 bool friction, Real positionStep,
                                                 std::span<const Real> solveImpulses) const {
  ColliderResponseReport report;
  report.constrainedVertices = Index(m_constrained.size());
  if (colliders.empty()) return report;
  WEFT_PROFILE_ZONE("response");
  for (Index i = 0; i < x.size(); ++i) {
    if (pinned[i]) continue;
    bool touched = false;
    for (const ColliderFrame& collider : colliders) {
      const Shape& shape = *collider.shape;
      // A vertex the solve pressed onto a collider ends at the thickness (to round-off, and a
      // little outside it on a curved body): it is in contact and takes friction all the same.
      // Counted as clear, a resting cloth took none from its constrained vertices (on a 5°
      // incline at μ 0.3 the column that round-off left a hair outside slid 0.22 mm a frame
      // while the others stuck, and the strain reached 2 %).
      const Real distance = queryPoint(shape, x[i]).distance;
      const bool pressed = !solveImpulses.empty() && solveImpulses[i] > 0 &&
                           distance < (1 + kPressedShell) * thickness;
      const bool endClear = distance >= thickness && !pressed;
      bool sweptHit = false;
      const Vec3 outside = keepOutside(collider, xStart[i], x[i], thickness, &sweptHit);
      if (endClear && !sweptHit) continue;  // neither near at the end nor met on the way
      if (endClear) ++report.sweptHits;
      x[i] = outside;
      const ShapeContact contact = queryPoint(shape, x[i]);
      // Inelastic: no relative velocity into the surface.
      const Vec3 relative = v[i] - contact.velocity;
      const Real normalSpeed = relative.dot(contact.normal);
      Vec3 normalPart = normalSpeed * contact.normal;
      const Vec3 tangential = relative - normalPart;
      if (normalSpeed < 0) normalPart.setZero();
      // Coulomb friction: the normal velocity change over the step (from the solve's constraint
      // and from this pass) bounds how much tangential velocity friction may remove.
      const Real solvePart = solveImpulses.empty()
                                 ? std::max<Real>(0, (v[i] - vStart[i]).dot(contact.normal))
                                 : std::max<Real>(0, solveImpulses[i]);
      const Real normalChange = solvePart + std::max<Real>(0, -normalSpeed);
      const Vec3 kept = friction ? coulombFriction(tangential, normalChange, collider.friction)
                                 : tangential;
      v[i] = contact.velocity + normalPart + kept;
      if (positionStep > 0 && !touched && kept != tangential &&
          queryPoint(shape, collider.end.pose.toWorld(collider.start.pose.toLocal(xStart[i])))
                  .distance < (1 + kPressedShell) * thickness) {
        // x = x₀ + h v with the velocity after friction: a sticking contact stays where it
        // was. The shift is along the surface, tested against this collider like any motion
        // (not for a vertex already on another collider, whose corner it could push it into).
        // Only for a contact that began the step on the body (its start carried with the body
        // within the shell): the end of one that met it in the step is where its path relative
        // to the body slid on from the hit, not x₀ + h v, and shifting it by friction's whole
        // velocity change as well tore the sheet the 250 m/s sphere of the stress suite hits
        // (max strain 9.1 against 0.108).
        ColliderFrame still = collider;
        still.start = collider.end;
        x[i] = keepOutside(still, x[i], x[i] + positionStep * (kept - tangential), thickness);
      }
      if (holds) {
        // A second surface at an angle to the first leaves the vertex no direction to slide in.
        Vec3& held = holds->normals[i];
        if (held.isZero()) {
          held = contact.normal;
        } else if (std::abs(held.dot(contact.normal)) < kSameNormal) {
          holds->fixed[i] = 1;
        }
      }
      touched = true;
    }
    report.contacts += touched ? 1 : 0;
  }
  return report;
}

}  // namespace weft
