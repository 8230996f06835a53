#include "contact/ContactProjector.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

// A vertex within this fraction of the thickness beyond a collider is on it at the end of the
// projection (its normal velocity is made inelastic): the projection leaves contacts at exactly
// the thickness, a body's curvature a little beyond.
constexpr Real kOnSurfaceShell = 0.01;
// m: face points closer than this outside their reach still count as touching (a point the
// projection just put at the reach is at −1e-17).
constexpr Real kTouching = 1e-9;

// The inverse mass every movable vertex of a pair counts with (the pair's heaviest) and the sum
// Σ w_k² W over its movable vertices; 0 when none can move.
std::pair<Real, Real> pairInverseMass(const Contact& contact, std::span<const Real> inverseMasses) {
  Real heaviest = std::numeric_limits<Real>::infinity();
  for (int k = 0; k < 4; ++k) {
    const Real w = inverseMasses[contact.vertices[k]];
    if (w > 0 && contact.weights[k] != 0) heaviest = std::min(heaviest, w);
  }
  if (!std::isfinite(heaviest)) return {0, 0};
  Real sum = 0;
  for (int k = 0; k < 4; ++k) {
    if (inverseMasses[contact.vertices[k]] > 0) sum += contact.weights[k] * contact.weights[k];
  }
  return {heaviest, sum * heaviest};
}

// The friction correction that replaces `applied` for a tangential slip `slip` (measured with
// `applied` in place) under the normal displacement budget `normal` (see the file comment).
Vec3 frictionCorrection(const Vec3& slip, const Vec3& applied, Real normal, Real friction) {
  const Vec3 free = slip - applied;
  return coulombFriction(free, normal, friction) - free;
}

}  // namespace

ProjectionReport ContactProjector::project(ContactSpace& space, const ContactSet& set,
                                           std::span<const ColliderFrame> colliders, Real h,
                                           const ProjectionSettings& settings,
                                           std::vector<FaceSupport>& supports) {
  WEFT_PROFILE_ZONE("project");
  ProjectionReport report;
  const std::size_t count = set.size();
  m_pushed.assign(count, 0);
  m_friction.assign(count, Vec3::Zero());
  m_lastOutside.resize(count);
  for (std::size_t c = 0; c < set.firstPair; ++c) {
    const Contact& contact = set.contacts[c];
    if (contact.kind == ContactKind::VertexCollider) {
      m_lastOutside[c] = colliders[contact.collider].carry(space.startX[contact.vertices[0]]);
    }
  }
  const Real inverseStep = 1 / h;
  for (int iteration = 0;; ++iteration) {
    const bool backward = iteration % 2 == 1;
    const Index over = sweepEdges(space, inverseStep, settings.strainTolerance, backward);
    const Index violated =
        sweepContacts(space, set, colliders, h, settings.contactTolerance, backward);
    report.edgesOverLimit = over;
    report.contactsViolated = violated;
    if (over == 0 && violated == 0) break;
    report.iterations = iteration + 1;
    if (report.iterations == settings.maxIterations) {
      // What the last sweeps left, measured without correcting.
      report.edgesOverLimit = 0;
      for (std::size_t e = 0; e < space.edges.size(); ++e) {
        const Real length = (space.x[space.edges[e][1]] - space.x[space.edges[e][0]]).norm();
        report.edgesOverLimit +=
            length > space.longest[e] + settings.strainTolerance * space.restLengths[e];
      }
      break;
    }
  }
  report.colliderContacts = finish(space, set, colliders, h, supports);
  return report;
}

Index ContactProjector::sweepEdges(ContactSpace& space, Real inverseStep, Real tolerance,
                                   bool backward) {
  const Index edgeCount = Index(space.edges.size());
  Index over = 0;
  for (Index k = 0; k < edgeCount; ++k) {
    const Index e = backward ? edgeCount - 1 - k : k;
    const Real longest = space.longest[e];
    const Index a = space.edges[e][0], b = space.edges[e][1];
    const Vec3 delta = space.x[b] - space.x[a];
    const Real length = delta.norm();
    if (!(length > longest)) continue;
    const Real weightA = space.inverseMass[a], weightB = space.inverseMass[b];
    const Real weightSum = weightA + weightB;
    if (weightSum == 0) continue;  // both ends pinned: nothing can shorten it
    over += length > longest + tolerance * space.restLengths[e];
    const Vec3 impulse = ((length - longest) / (weightSum * length)) * delta;
    space.x[a] += weightA * impulse;
    space.v[a] += inverseStep * weightA * impulse;
    space.x[b] -= weightB * impulse;
    space.v[b] -= inverseStep * weightB * impulse;
  }
  return over;
}

Index ContactProjector::sweepContacts(ContactSpace& space, const ContactSet& set,
                                      std::span<const ColliderFrame> colliders, Real h,
                                      Real tolerance, bool backward) {
  Index violated = 0;
  const std::size_t count = set.size();
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t c = backward ? count - 1 - k : k;
    const Contact& contact = set.contacts[c];
    Real depth = 0;
    switch (contact.kind) {
      case ContactKind::VertexCollider:
        depth = projectVertex(space, c, contact, colliders[contact.collider], h);
        break;
      case ContactKind::FaceCollider:
        depth = projectFace(space, c, contact, set, colliders[contact.collider], h);
        break;
      case ContactKind::VertexFace:
      case ContactKind::EdgeEdge:
        depth = projectPair(space, c, contact, h);
        break;
    }
    violated += depth > tolerance * contact.separation;
  }
  return violated;
}

Real ContactProjector::projectVertex(ContactSpace& space, std::size_t index,
                                     const Contact& contact, const ColliderFrame& collider,
                                     Real h) {
  const Index i = contact.vertices[0];
  const Real thickness = contact.separation;
  Vec3& x = space.x[i];
  const ShapeContact before = queryPoint(collider.shape, x);
  Real depth = 0;
  if (before.distance < thickness) {
    depth = thickness - before.distance;
    // Followed from where it was last outside, the body held at its end pose.
    const Vec3 outside = keepOutsideFrom(collider.shape, m_lastOutside[index], x, thickness);
    const Vec3 shift = outside - x;
    x = outside;
    space.v[i] += shift / h;
    m_pushed[index] += std::max<Real>(0, shift.dot(queryPoint(collider.shape, x).normal));
  }
  m_lastOutside[index] = x;
  if (!contact.resting || !(contact.friction > 0)) return depth;
  // Static and kinetic friction on the substep's displacement relative to the body.
  const ShapeContact on = queryPoint(collider.shape, x);
  if (!(on.distance < (1 + kOnSurfaceShell) * thickness)) return depth;
  const Real normal = h * contact.solveImpulse + m_pushed[index];
  Vec3 slip = x - collider.carry(space.startX[i]);
  slip -= slip.dot(on.normal) * on.normal;
  Vec3 applied = m_friction[index];
  applied -= applied.dot(on.normal) * on.normal;
  const Vec3 correction = frictionCorrection(slip, applied, normal, contact.friction);
  const Vec3 shift = correction - applied;
  x += shift;
  space.v[i] += shift / h;
  m_friction[index] = correction;
  return depth;
}

Real ContactProjector::projectFace(ContactSpace& space, std::size_t index, const Contact& contact,
                                   const ContactSet& set, const ColliderFrame& collider, Real h) {
  const std::array<Index, 3> corner{contact.vertices[0], contact.vertices[1], contact.vertices[2]};
  Vec3 normal = Vec3::Zero();
  const Real depth = pushFaceOut(set.cores[contact.core], contact.normal, collider.end.pose, corner,
                                 space.inverseMass, space.x, space.v, 1 / h, normal);
  m_pushed[index] += depth;
  if (!contact.resting || !(contact.friction > 0)) return depth;
  // Friction at the face's centroid over the corners that are not on the body themselves (those
  // take it as vertex contacts), with the body's normal where the face touches it.
  const Real thickness = space.owners[space.owner[corner[0]]].thickness;
  Vec3 b = Vec3::Zero();
  for (int j = 0; j < 3; ++j) {
    const bool onBody = queryPoint(collider.shape, space.x[corner[j]]).distance <
                        (1 + kOnSurfaceShell) * thickness;
    if (!onBody && space.inverseMass[corner[j]] > 0) b[j] = 1;
  }
  if (b.sum() == 0) return depth;
  b /= b.sum();
  if (normal.isZero()) {
    // Not pushed this sweep: the direction from the core to the face point now.
    const FaceCore& core = set.cores[contact.core];
    Vec3 point = Vec3::Zero();
    for (int j = 0; j < 3; ++j) point += b[j] * space.x[corner[j]];
    const Vec3 local = collider.end.pose.toLocal(point);
    const Vec3 segment = core.end - core.start;
    const Real s = segment.squaredNorm() > 0
                       ? std::clamp<Real>((local - core.start).dot(segment) / segment.squaredNorm(), 0, 1)
                       : 0;
    const Vec3 away = local - (core.start + s * segment);
    if (!(away.norm() < core.reach + (1 + kOnSurfaceShell) * thickness)) return depth;  // clear
    normal = collider.end.pose.directionToWorld(away.normalized());
  }
  const Real weight = pointInverseMass(b, corner, space.inverseMass);
  if (!(weight > 0)) return depth;
  const Real budget = h * contact.solveImpulse + m_pushed[index];
  Vec3 slip = Vec3::Zero();
  for (int j = 0; j < 3; ++j) slip += b[j] * (space.x[corner[j]] - collider.carry(space.startX[corner[j]]));
  slip -= slip.dot(normal) * normal;
  Vec3 applied = m_friction[index];
  applied -= applied.dot(normal) * normal;
  const Vec3 correction = frictionCorrection(slip, applied, budget, contact.friction);
  const Vec3 change = correction - applied;
  for (int j = 0; j < 3; ++j) {
    const Vec3 shift = (b[j] * space.inverseMass[corner[j]] / weight) * change;
    space.x[corner[j]] += shift;
    space.v[corner[j]] += shift / h;
  }
  m_friction[index] = correction;
  return depth;
}

Real ContactProjector::projectPair(ContactSpace& space, std::size_t index, const Contact& contact,
                                   Real h) {
  const auto [inverseMass, weight] = pairInverseMass(contact, space.inverseMass);
  if (!(weight > 0)) return 0;
  Vec3 gap = Vec3::Zero();
  for (int k = 0; k < 4; ++k) gap += contact.weights[k] * space.x[contact.vertices[k]];
  const Real shortfall = contact.separation - contact.normal.dot(gap);
  const auto move = [&](const Vec3& relativeChange) {
    const Vec3 lambda = relativeChange / weight;
    for (int k = 0; k < 4; ++k) {
      const Index i = contact.vertices[k];
      if (space.inverseMass[i] == 0) continue;
      const Vec3 shift = (contact.weights[k] * inverseMass) * lambda;
      space.x[i] += shift;
      space.v[i] += shift / h;
    }
  };
  if (shortfall > 0) {
    move(shortfall * contact.normal);
    m_pushed[index] += shortfall;
  }
  if (!(contact.friction > 0) || !(m_pushed[index] > 0)) return std::max<Real>(0, shortfall);
  // The relative tangential displacement of the two sides over the substep.
  Vec3 slip = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    const Index i = contact.vertices[k];
    slip += contact.weights[k] * (space.x[i] - space.startX[i]);
  }
  slip -= slip.dot(contact.normal) * contact.normal;
  const Vec3 correction =
      frictionCorrection(slip, m_friction[index], m_pushed[index], contact.friction);
  move(correction - m_friction[index]);
  m_friction[index] = correction;
  return std::max<Real>(0, shortfall);
}

Index ContactProjector::finish(ContactSpace& space, const ContactSet& set,
                               std::span<const ColliderFrame> colliders, Real h,
                               std::vector<FaceSupport>& supports) {
  supports.clear();
  Index onColliders = 0;
  for (std::size_t c = 0; c < set.size(); ++c) {
    const Contact& contact = set.contacts[c];
    if (contact.kind == ContactKind::VertexCollider) {
      const Index i = contact.vertices[0];
      const ColliderFrame& collider = colliders[contact.collider];
      const ShapeContact on = queryPoint(collider.shape, space.x[i]);
      if (!(on.distance < (1 + kOnSurfaceShell) * contact.separation)) continue;
      ++onColliders;
      // Inelastic: no relative velocity into the surface.
      const Vec3 relative = space.v[i] - on.velocity;
      const Real normalSpeed = relative.dot(on.normal);
      const Vec3 tangential = relative - normalSpeed * on.normal;
      const Real removed = std::max<Real>(0, -normalSpeed);
      Vec3 kept = tangential;
      if (!contact.resting && contact.friction > 0) {
        // Met the body within the substep: friction on the velocity, bounded by the normal
        // velocity change (the solve's, the projection's and this one's).
        kept = coulombFriction(tangential, contact.solveImpulse + m_pushed[c] / h + removed,
                               contact.friction);
      }
      space.v[i] = on.velocity + std::max<Real>(0, normalSpeed) * on.normal + kept;
    } else if (contact.kind == ContactKind::FaceCollider) {
      const ColliderFrame& collider = colliders[contact.collider];
      const RigidMotion& body = collider.end;
      const std::array<Index, 3> corner{contact.vertices[0], contact.vertices[1],
                                        contact.vertices[2]};
      std::array<Vec3, 3> local;
      for (int j = 0; j < 3; ++j) local[j] = body.pose.toLocal(space.x[corner[j]]);
      std::array<FacePoint, 3> points;
      const FaceCore& core = set.cores[contact.core];
      // A face the projection pushed keeps the body's pace even where a later push carried it a
      // little past the reach; the others count where they touch.
      const Real minDepth = m_pushed[c] > 0 ? -std::numeric_limits<Real>::infinity() : -kTouching;
      const int touching =
          facePoints(core, contact.normal, local[0], local[1], local[2], minDepth, points);
      if (touching > 0) ++onColliders;
      for (int p = 0; p < touching; ++p) {
        const FacePoint& point = points[p];
        const Vec3& b = point.barycentric;
        const Vec3 normal = body.pose.directionToWorld(point.normal);
        supports.push_back({corner, b, normal,
                            normal.dot(body.pose.toWorld(point.corePoint)) + core.reach});
        const Real weight = pointInverseMass(b, corner, space.inverseMass);
        if (!(weight > 0)) continue;
        Vec3 facePoint = Vec3::Zero(), faceVelocity = Vec3::Zero();
        for (int j = 0; j < 3; ++j) {
          facePoint += b[j] * space.x[corner[j]];
          faceVelocity += b[j] * space.v[corner[j]];
        }
        const Real approach = (faceVelocity - body.velocityAt(facePoint)).dot(normal);
        if (!(approach < 0)) continue;
        for (int j = 0; j < 3; ++j) {
          space.v[corner[j]] -= (b[j] * space.inverseMass[corner[j]] / weight * approach) * normal;
        }
      }
    } else {
      // A pair in contact keeps no relative velocity into itself.
      const auto [inverseMass, weight] = pairInverseMass(contact, space.inverseMass);
      if (!(weight > 0)) continue;
      Vec3 gap = Vec3::Zero(), relative = Vec3::Zero();
      for (int k = 0; k < 4; ++k) {
        gap += contact.weights[k] * space.x[contact.vertices[k]];
        relative += contact.weights[k] * space.v[contact.vertices[k]];
      }
      if (contact.normal.dot(gap) > (1 + kOnSurfaceShell) * contact.separation) continue;
      const Real normalSpeed = relative.dot(contact.normal);
      if (!(normalSpeed < 0)) continue;
      const Real lambda = -normalSpeed / weight;
      for (int k = 0; k < 4; ++k) {
        const Index i = contact.vertices[k];
        if (space.inverseMass[i] == 0) continue;
        space.v[i] += (contact.weights[k] * inverseMass * lambda) * contact.normal;
      }
    }
  }
  return onColliders;
}

}  // namespace weft
