#include "ColliderFaceContacts.h"

#include <weft/collision/Proximity.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <variant>

namespace weft {
namespace {

// Sweeps over the contacts at most: the first finds and resolves them, later ones fix what a
// neighbouring face's correction undid. Faces rarely share a contact with more than two or three
// neighbours, so the sweeps converge fast; what is left is within the vertices' thickness.
constexpr int kMaxSweeps = 4;
// A sweep that moved no face point farther than this fraction of the body's radius ends the
// loop: round-off, not contact.
constexpr Real kSettledFraction = 1e-6;

// The core of a round body in its own frame (the sphere's centre is a segment of length 0) and
// its radius; false for other shapes.
bool roundCore(const Shape& shape, Vec3& coreStart, Vec3& coreEnd, Real& radius) {
  if (const Sphere* sphere = std::get_if<Sphere>(&shape)) {
    coreStart = coreEnd = Vec3::Zero();
    radius = sphere->radius();
    return true;
  }
  if (const Capsule* capsule = std::get_if<Capsule>(&shape)) {
    coreStart = Vec3(0, -capsule->halfLength(), 0);
    coreEnd = Vec3(0, capsule->halfLength(), 0);
    radius = capsule->radius();
    return true;
  }
  return false;
}

}  // namespace

ColliderFaceReport ColliderFaceContacts::resolve(std::span<const ColliderFrame> colliders,
                                                 std::span<const TriangleRest> triangles,
                                                 const Vec3Array& xStart,
                                                 std::span<const Real> inverseMasses,
                                                 Real allowance, Vec3Array& x, Vec3Array& v) {
  ColliderFaceReport report;
  m_holds.clear();
  m_candidates.clear();
  WEFT_PROFILE_ZONE("face contacts");
  for (Index k = 0; k < Index(colliders.size()); ++k) {
    Vec3 coreStart, coreEnd;
    Real radius = 0;
    if (!roundCore(*colliders[k].shape, coreStart, coreEnd, radius)) continue;
    const Aabb body = bounds(*colliders[k].shape);
    for (Index t = 0; t < Index(triangles.size()); ++t) {
      const std::array<Index, 3>& corner = triangles[t].vertices;
      if (inverseMasses[corner[0]] == 0 && inverseMasses[corner[1]] == 0 &&
          inverseMasses[corner[2]] == 0) {
        continue;
      }
      Aabb box = Aabb::empty();
      for (Index i : corner) box.expand(x[i]);
      if (box.overlaps(body)) m_candidates.push_back({t, k, false, {}, Vec3::Zero()});
    }
  }
  if (m_candidates.empty()) return report;

  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    ++report.sweeps;
    bool moved = false;
    for (Candidate& candidate : m_candidates) {
      const ColliderFrame& collider = colliders[candidate.collider];
      Vec3 coreStart, coreEnd;
      Real radius = 0;
      (void)roundCore(*collider.shape, coreStart, coreEnd, radius);
      const Real reach = radius - allowance;  // faces are kept this far from the core
      const std::array<Index, 3>& corner = triangles[candidate.triangle].vertices;
      const Pose& endPose = collider.end.pose;
      const SegmentTriangleClosestPoints now = closestPointsOnSegmentAndTriangle(
          coreStart, coreEnd, endPose.toLocal(x[corner[0]]), endPose.toLocal(x[corner[1]]),
          endPose.toLocal(x[corner[2]]));
      if (!(now.distance < reach)) continue;
      // The side the face is on: its own normal, unless it reached the core or crossed it within
      // the step (then the start's normal, where the face came from).
      const Pose& startPose = collider.start.pose;
      const SegmentTriangleClosestPoints before = closestPointsOnSegmentAndTriangle(
          coreStart, coreEnd, startPose.toLocal(xStart[corner[0]]),
          startPose.toLocal(xStart[corner[1]]), startPose.toLocal(xStart[corner[2]]));
      Vec3 normal = Vec3::Zero();
      if (now.distance > 0) normal = (now.pointOnTriangle - now.pointOnSegment) / now.distance;
      if (before.distance > 0) {
        const Vec3 cameFrom = (before.pointOnTriangle - before.pointOnSegment) / before.distance;
        if (now.distance == 0 || normal.dot(cameFrom) < 0) normal = cameFrom;
      }
      if (normal.isZero()) continue;  // inside the core at both ends: no side to choose
      const Real depth = reach - normal.dot(now.pointOnTriangle - now.pointOnSegment);
      if (!(depth > 0)) continue;
      const Vec3& b = now.barycentric;
      Real weight = 0;
      for (int j = 0; j < 3; ++j) weight += b[j] * b[j] * inverseMasses[corner[j]];
      if (!(weight > 0)) continue;
      const Vec3 worldNormal = endPose.directionToWorld(normal);
      const Vec3 corePoint = endPose.toWorld(now.pointOnSegment);
      for (int j = 0; j < 3; ++j) {
        x[corner[j]] += (b[j] * inverseMasses[corner[j]] / weight * depth) * worldNormal;
      }
      if (sweep == 0) ++report.contacts;
      moved = moved || depth > kSettledFraction * radius;
      // One hold per face and body, from its last correction: the limiter keeps the face point
      // on the surface along this normal.
      candidate.touched = true;
      candidate.hold.vertices = {corner[0], corner[1], corner[2], corner[0]};
      candidate.hold.weights = {b[0], b[1], b[2], 0};
      candidate.hold.normal = worldNormal;
      candidate.hold.separation = worldNormal.dot(corePoint) + reach;
      candidate.barycentric = b;
    }
    if (!moved) break;
  }
  // Inelastic, once the positions have settled: each face point keeps no velocity into the body
  // (relative to the body's surface there). Done per sweep instead, every contact of a face that
  // several sweeps correct adds its own push and the face leaves faster than the body (a rod
  // rising at 1.8 m/s into a face sent its corners off at up to 2.5 m/s).
  for (const Candidate& candidate : m_candidates) {
    if (!candidate.touched) continue;
    m_holds.push_back(candidate.hold);
    const std::array<Index, 3>& corner = triangles[candidate.triangle].vertices;
    const Vec3& b = candidate.barycentric;
    Real weight = 0;
    Vec3 facePoint = Vec3::Zero(), faceVelocity = Vec3::Zero();
    for (int j = 0; j < 3; ++j) {
      weight += b[j] * b[j] * inverseMasses[corner[j]];
      facePoint += b[j] * x[corner[j]];
      faceVelocity += b[j] * v[corner[j]];
    }
    const Vec3& normal = candidate.hold.normal;
    const Vec3 bodyVelocity = colliders[candidate.collider].end.velocityAt(facePoint);
    const Real approach = (faceVelocity - bodyVelocity).dot(normal);
    if (approach < 0) {
      for (int j = 0; j < 3; ++j) {
        v[corner[j]] -= (b[j] * inverseMasses[corner[j]] / weight * approach) * normal;
      }
    }
  }
  return report;
}

}  // namespace weft
