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
// A projection stopped at its sweep cap reports the contacts it left short of their separation by
// more than this share of their thickness (StepStatus::ContactsUnresolved): ten times the
// tolerance it works to, so that a contact still converging in its last per cent at the cap
// (a face on a finely meshed rod) is not reported, and one the cap cut short is.
constexpr Real kUnresolvedShortfall = 0.1;
// Friction acts in every sweep, its accumulated correction bounded by the contact's budget, so
// the sweeps that satisfy the strain limit and the separations cannot undo what it holds (a
// towel resting on a rod by its faces would creep along it).
constexpr int kFrictionSweeps = std::numeric_limits<int>::max();
// Sweeps in which a change of friction alone keeps the projection going (the header says why it
// stops counting).
constexpr int kFrictionCountedSweeps = 16;
// Sweeps in which the edges follow the leader (only the end farther from the pins moves): the first
// brings a hanging chain within its limit from the pins down in one pass; the later ones share
// each correction by mass, which lets a load from the far side (a body pushing the cloth's middle)
// draw cloth in from the pins.
constexpr int kFollowTheLeaderSweeps = 1;
// The sweep from which the projector tries listing the edges left to visit instead of scanning
// every edge (VisitSet.h), and tries again at every power of two after while too many are left:
// most projections end sooner, and a try costs about one scan.
constexpr int kTrackingFromSweep = 4;
// m: face points closer than this outside their reach still count as touching (a point the
// projection just put at the reach is at −1e-17).
constexpr Real kTouching = 1e-9;

// Below this fraction of the free weight sum, an edge held at both ends along itself is left to
// the contacts (it cannot be shortened across the surfaces it rests on), and a pair whose movable
// vertices carry less than this fraction of its Σ w_k² is left to the impact pass (they would
// have to move by its shortfall / w_k: a point on a face whose pinned corners collapsed together
// flew 10¹² m).
constexpr Real kSmallestHeldWeight = 1e-3;

// The inverse mass every movable vertex of a pair counts with (the pair's heaviest) and the sum
// Σ w_k² W over its movable vertices; 0 when none can move, or too little (kSmallestHeldWeight).
std::pair<Real, Real> pairInverseMass(const Contact& contact, std::span<const Real> inverseMasses) {
  Real heaviest = std::numeric_limits<Real>::infinity();
  for (int k = 0; k < 4; ++k) {
    const Real w = inverseMasses[contact.vertices[k]];
    if (w > 0 && contact.weights[k] != 0) heaviest = std::min(heaviest, w);
  }
  if (!std::isfinite(heaviest)) return {0, 0};
  Real sum = 0, whole = 0;
  for (int k = 0; k < 4; ++k) {
    const Real square = contact.weights[k] * contact.weights[k];
    whole += square;
    if (inverseMasses[contact.vertices[k]] > 0) sum += square;
  }
  if (!(sum >= kSmallestHeldWeight * whole)) return {0, 0};
  return {heaviest, sum * heaviest};
}

// The friction correction that replaces `applied` for a tangential slip `slip` (measured with
// `applied` in place) under the normal displacement budget `normal` (see the file comment).
Vec3 frictionCorrection(const Vec3& slip, const Vec3& applied, Real normal, Real friction) {
  const Vec3 free = slip - applied;
  return coulombFriction(free, normal, friction) - free;
}

// An edge's weight sum when its ends may move only across their contact normals (zero normal:
// free): w (1 − (n·d)²) per end, d the edge's direction.
Real heldWeight(Real weightA, Real weightB, const Vec3& normalA, const Vec3& normalB,
                const Vec3& direction) {
  const Real alongA = normalA.dot(direction), alongB = normalB.dot(direction);
  const Real held = weightA * (1 - alongA * alongA) + weightB * (1 - alongB * alongB);
  return held > kSmallestHeldWeight * (weightA + weightB) ? held : 0;
}

// The fraction of a held correction that brings the edge vector `delta`, changed by `change`, to
// length `longest` (the first root), or where it is shortest when it cannot get that short: the
// correction is linearised, and across a normal nearly along the edge it would carry an end far
// past the edge's shortest point.
Real heldStepFraction(const Vec3& delta, const Vec3& change, Real longest) {
  const Real a = change.squaredNorm(), b = delta.dot(change);
  if (!(a > 0) || !(b < 0)) return 0;
  const Real c = delta.squaredNorm() - longest * longest;
  const Real discriminant = b * b - a * c;
  const Real fraction = discriminant >= 0 ? (-b - std::sqrt(discriminant)) / a : -b / a;
  return std::min<Real>(1, fraction);
}

}  // namespace

ProjectionReport ContactProjector::project(ContactSpace& space, const ContactSet& set,
                                           std::span<const ColliderFrame> colliders, Real h,
                                           const ProjectionSettings& settings,
                                           std::vector<FaceSupport>& supports) {
  WEFT_PROFILE_ZONE("project");
  // The sweep order and the vertex → edge table are the space's; a space put together by hand
  // (tests) gets them here.
  if (!space.edgeSlotsListed()) space.listEdgeSlots();
  ProjectionReport report;
  const std::size_t count = set.size();
  m_pushed.assign(count, 0);
  m_visited.assign(count, 0);
  m_contactSeenMoves.assign(count, std::numeric_limits<std::uint64_t>::max());
  // A vertex on two colliders takes its surface normal from the one visited last: its contacts
  // are never skipped, so that the normal stays the one a full sweep leaves.
  m_colliderContactsOf.assign(space.vertexCount(), 0);
  for (const Contact& contact : set.contacts) {
    if (contact.kind != ContactKind::VertexCollider) continue;
    std::uint8_t& contacts = m_colliderContactsOf[contact.vertices[0]];
    contacts = std::min<std::uint8_t>(contacts + 1, 2);
  }
  m_moves.assign(space.vertexCount(), 0);
  m_edgeSeenMoves.assign(space.edges.size(), std::numeric_limits<std::uint64_t>::max());
  m_trackingEdges = false;
  m_solved = space.x;
  m_touching.assign(space.vertexCount(), 0);
  m_surfaceNormal.assign(space.vertexCount(), Vec3::Zero());
  for (const Contact& contact : set.contacts) {
    for (Index vertex : contact.vertices) {
      if (vertex != kInvalidIndex) m_touching[vertex] = 1;
    }
  }
  m_friction.assign(count, Vec3::Zero());
  m_lastOutside.resize(count);
  // The pairs' masses stay as they are through the sweeps.
  m_pairMass.assign(count, {0, 0});
  for (std::size_t c = set.firstPair; c < count; ++c) {
    m_pairMass[c] = pairInverseMass(set.contacts[c], space.inverseMass);
  }
  for (int iteration = 0;; ++iteration) {
    if (!m_trackingEdges && iteration >= kTrackingFromSweep && (iteration & (iteration - 1)) == 0) {
      startTracking(space);
    }
    const bool backward = iteration % 2 == 1;
    m_frictionOn = iteration < kFrictionSweeps;
    m_frictionCounted = iteration < kFrictionCountedSweeps;
    m_followTheLeader = iteration < kFollowTheLeaderSweeps;
    const Index over = sweepEdges(space, settings.strainTolerance, backward);
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
      report.contactsViolated = unseparatedContacts(space, set, colliders, kUnresolvedShortfall);
      break;
    }
  }
  // The projection's whole displacement becomes the velocity's change, so v stays the substep's
  // average velocity (x − x₀) / h; then contacts keep no velocity into each other.
  const Real inverseStep = 1 / h;
  for (Index i = 0; i < space.vertexCount(); ++i) space.v[i] += (space.x[i] - m_solved[i]) * inverseStep;
  report.colliderContacts = finish(space, set, colliders, supports);
  return report;
}

void ContactProjector::startTracking(const ContactSpace& space) {
  // The edges a full sweep would not skip. Tracked once at most half of them are: where most
  // edges move every sweep, listing them costs more than the scan it saves.
  const Index edgeCount = Index(space.edges.size());
  m_pendingEdges.reset(edgeCount, false);
  Index pending = 0;
  for (Index slot = 0; slot < edgeCount; ++slot) {
    const Index e = space.edgeOrder[slot];
    const std::uint64_t moves = std::uint64_t(m_moves[space.edges[e][0]]) + m_moves[space.edges[e][1]];
    if (moves != m_edgeSeenMoves[e]) {
      m_pendingEdges.insert(slot);
      ++pending;
    }
  }
  if (2 * pending > edgeCount) return;
  m_edgeSlotBegin = space.edgeSlotBegin;
  m_edgeSlots = space.edgeSlots;
  // Every tether once more in the first tracked sweep, as in an untracked one.
  m_tethered = std::min<Index>(space.vertexCount(), Index(space.tetherAnchor.size()));
  m_pendingTethers.reset(m_tethered, true);
  m_edgesPending.assign(space.vertexCount(), 0);
  m_trackingEdges = true;
}

Index ContactProjector::unseparatedContacts(const ContactSpace& space, const ContactSet& set,
                                            std::span<const ColliderFrame> colliders,
                                            Real shortfall) const {
  // Separation only: a sweep's own count also holds the friction corrections still moving.
  Index count = 0;
  for (const Contact& contact : set.contacts) {
    const Real slack = shortfall * space.owners[space.owner[contact.vertices[0]]].thickness;
    switch (contact.kind) {
      case ContactKind::VertexCollider:
        count += queryPointBelow(colliders[contact.collider].shape, space.x[contact.vertices[0]],
                                 contact.separation - slack)
                     .has_value();
        break;
      case ContactKind::FaceCollider: {
        const Pose& pose = colliders[contact.collider].end.pose;
        std::array<FacePoint, 3> points;
        count += facePoints(set.cores[contact.core], contact.normal,
                            pose.toLocal(space.x[contact.vertices[0]]),
                            pose.toLocal(space.x[contact.vertices[1]]),
                            pose.toLocal(space.x[contact.vertices[2]]), slack, points) > 0;
        break;
      }
      case ContactKind::VertexFace:
      case ContactKind::EdgeEdge: {
        count += contact.normal.dot(contact.relativePosition(space.x)) < contact.separation - slack;
        break;
      }
    }
  }
  return count;
}

std::uint64_t ContactProjector::movesOf(const Contact& contact) const {
  std::uint64_t moves = 0;
  for (Index vertex : contact.vertices) {
    if (vertex != kInvalidIndex) moves += m_moves[vertex];
  }
  return moves;
}

void ContactProjector::markIfWithin(const ContactSpace& space, Index e, Index slot) {
  const Index a = space.edges[e][0], b = space.edges[e][1];
  // Measured as the sweep measures it: a correction can leave the edge a rounding error long.
  if ((space.x[b] - space.x[a]).norm() <= space.longest[e]) {
    m_edgeSeenMoves[e] = std::uint64_t(m_moves[a]) + m_moves[b];
    if (m_trackingEdges) settle(slot, a, b);
  }
}

void ContactProjector::listEdgesOf(Index vertex) {
  for (Index k = m_edgeSlotBegin[vertex]; k < m_edgeSlotBegin[vertex + 1]; ++k) {
    m_pendingEdges.insert(m_edgeSlots[k]);
  }
  if (vertex < m_tethered) m_pendingTethers.insert(vertex);
  m_edgesPending[vertex] = 1;
}

void ContactProjector::settle(Index slot, Index a, Index b) {
  m_pendingEdges.erase(slot);
  m_edgesPending[a] = m_edgesPending[b] = 0;
}

Index ContactProjector::sweepEdges(ContactSpace& space, Real tolerance, bool backward) {
  return m_trackingEdges ? sweepEdgesAs<true>(space, tolerance, backward)
                         : sweepEdgesAs<false>(space, tolerance, backward);
}

template <bool tracking>
Index ContactProjector::sweepEdgesAs(ContactSpace& space, Real tolerance, bool backward) {
  const Index edgeCount = Index(space.edges.size());
  Index over = 0;
  // The tethers first: each moves its vertex only (the anchor is a pin, which the projection
  // never moves). Once tracking, only the vertices moved since their tether was last within.
  const Index tethered = std::min<Index>(space.vertexCount(), Index(space.tetherAnchor.size()));
  Index i = 0;
  if constexpr (tracking) i = m_pendingTethers.next(0);
  while (i < tethered) {
    const Index anchor = space.tetherAnchor[i];
    const bool tethers = anchor != kInvalidIndex && space.inverseMass[i] != 0;
    const Vec3 delta = tethers ? Vec3(space.x[i] - space.x[anchor]) : Vec3::Zero();
    const Real length = tethers ? delta.norm() : Real(0);
    const Real longest = space.tetherLength[i];
    if (!tethers || !(length > longest)) {
      if constexpr (tracking) {
        m_pendingTethers.erase(i);
        m_edgesPending[i] = 0;  // its next move lists the tether again
      }
    } else {
      over += length > longest * (1 + tolerance);
      const Vec3 shift = ((longest - length) / length) * delta;
      space.x[i] += shift;
      moved(i, shift != Vec3::Zero());
    }
    if constexpr (tracking) {
      i = m_pendingTethers.next(i + 1);
    } else {
      ++i;
    }
  }
  const bool anchored = space.anchorDistance.size() == space.x.size() && m_followTheLeader;
  // The next edge in sweep order; once tracking, those settled since their last visit left out.
  const auto following = [&](Index slot) {
    if constexpr (tracking) {
      return backward ? (slot == 0 ? kInvalidIndex : m_pendingEdges.previous(slot - 1))
                      : m_pendingEdges.next(slot + 1);
    } else {
      return backward ? slot - 1 : (slot + 1 < edgeCount ? slot + 1 : kInvalidIndex);
    }
  };
  Index first = backward ? edgeCount - 1 : 0;  // kInvalidIndex (no edges) when backward
  if constexpr (tracking) {
    first = backward ? m_pendingEdges.previous(first) : m_pendingEdges.next(first);
  } else if (edgeCount == 0) {
    first = kInvalidIndex;
  }
  for (Index slot = first; slot != kInvalidIndex; slot = following(slot)) {
    const Index e = space.edgeOrder[slot];
    const Index a = space.edges[e][0], b = space.edges[e][1];
    // Left within its limit at its last visit, and neither end moved since: still within it.
    const std::uint64_t moves = std::uint64_t(m_moves[a]) + m_moves[b];
    if (moves == m_edgeSeenMoves[e]) {
      if constexpr (tracking) settle(slot, a, b);
      continue;
    }
    const Real longest = space.longest[e];
    const Vec3 delta = space.x[b] - space.x[a];
    const Real length = delta.norm();
    if (!(length > longest)) {
      m_edgeSeenMoves[e] = moves;
      if constexpr (tracking) settle(slot, a, b);
      continue;
    }
    Real weightA = space.inverseMass[a], weightB = space.inverseMass[b];
    if (weightA + weightB == 0) {  // both ends pinned: nothing can shorten it
      m_edgeSeenMoves[e] = moves;
      if constexpr (tracking) settle(slot, a, b);
      continue;
    }
    over += length > longest + tolerance * space.restLengths[e];
    const Vec3& normalA = m_surfaceNormal[a];
    const Vec3& normalB = m_surfaceNormal[b];
    if (!normalA.isZero() || !normalB.isZero()) {
      // An end resting on a collider slides on it: its share of the correction loses the part
      // along the surface's normal, which the contact would undo (GS would then zig-zag along a
      // curved body), and the step is cut where it brings the edge to its limit.
      const Vec3 direction = delta / length;
      const Real held = heldWeight(weightA, weightB, normalA, normalB, direction);
      if (held == 0) continue;
      const Vec3 impulse = ((length - longest) / held) * direction;
      Vec3 shiftA = weightA * impulse, shiftB = -weightB * impulse;
      shiftA -= normalA.dot(shiftA) * normalA;
      shiftB -= normalB.dot(shiftB) * normalB;
      const Real fraction = heldStepFraction(delta, shiftB - shiftA, longest);
      space.x[a] += fraction * shiftA;
      space.x[b] += fraction * shiftB;
      moved(a, fraction * shiftA != Vec3::Zero());
      moved(b, fraction * shiftB != Vec3::Zero());
      markIfWithin(space, e, slot);
      continue;
    }
    // Follow the leader: the end nearer the pins stays, unless the other cannot move or either
    // end touches something (then the contact, not the pins, carries it: both ends move).
    if (anchored && !m_touching[a] && !m_touching[b]) {
      const Real nearA = space.anchorDistance[a], nearB = space.anchorDistance[b];
      if (nearA < nearB && weightB > 0) weightA = 0;
      if (nearB < nearA && weightA > 0) weightB = 0;
    }
    const Vec3 impulse = ((length - longest) / ((weightA + weightB) * length)) * delta;
    space.x[a] += weightA * impulse;
    space.x[b] -= weightB * impulse;
    moved(a, weightA > 0);
    moved(b, weightB > 0);
    markIfWithin(space, e, slot);
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
    // Its last visit moved nothing, and none of its vertices moved since: a visit now would
    // compute the same and move nothing again.
    const std::uint64_t moves = movesOf(contact);
    if (moves == m_contactSeenMoves[c]) continue;
    const bool revisit = m_visited[c] != 0;
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
    // A contact counts while it still moves its vertices (pushed out, or friction's stick).
    violated += depth > tolerance * space.owners[space.owner[contact.vertices[0]]].thickness;
    // A vertex contact's first visit follows the vertex's path, later ones do not: only a
    // later visit that moved nothing repeats itself.
    const bool sharedNormal = contact.kind == ContactKind::VertexCollider &&
                              m_colliderContactsOf[contact.vertices[0]] > 1;
    if (revisit && !sharedNormal && movesOf(contact) == moves) m_contactSeenMoves[c] = moves;
    m_visited[c] = 1;
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
  // Followed from where it was last outside, the body held at its end pose; on the first visit
  // along its whole path relative to the body over the substep, so that a vertex a fast or thin
  // body passed through is found although it ends clear of it.
  const bool firstVisit = !m_visited[index];
  Vec3 shift = Vec3::Zero();  // the push out, when one is taken
  if (before.distance < thickness || firstVisit) {
    const Vec3 outside =
        firstVisit ? keepOutside(collider, space.startX[i], x, thickness)
                   : keepOutsideFrom(collider.shape, m_lastOutside[index], x, thickness);
    if (!(outside - x).isZero()) {
      shift = outside - x;
      depth = std::max<Real>(thickness - before.distance, shift.norm());
      x = outside;
      moved(i);
    }
  }
  m_lastOutside[index] = x;
  const ShapeContact on = shift == Vec3::Zero() ? before : queryPoint(collider.shape, x);
  m_pushed[index] += std::max<Real>(0, shift.dot(on.normal));
  // Resting on the body now: the edges slide the vertex on it (sweepEdges).
  const bool onSurface = on.distance < (1 + kOnSurfaceShell) * thickness;
  m_surfaceNormal[i] = onSurface ? on.normal : Vec3::Zero();
  if (!m_frictionOn || !contact.resting || !(contact.friction > 0) || !onSurface) return depth;
  // Static and kinetic friction on the substep's displacement relative to the body.
  const Real normal = h * contact.solveImpulse +
                     std::max<Real>(0, on.normal.dot(x - m_solved[i]));
  Vec3 slip = x - collider.carry(space.startX[i]);
  slip -= slip.dot(on.normal) * on.normal;
  Vec3 applied = m_friction[index];
  applied -= applied.dot(on.normal) * on.normal;
  const Vec3 correction = frictionCorrection(slip, applied, normal, contact.friction);
  x += correction - applied;
  moved(i, correction != applied);
  m_friction[index] = correction;
  return std::max(depth, frictionViolation((correction - applied).norm()));
}

Real ContactProjector::projectFace(ContactSpace& space, std::size_t index, const Contact& contact,
                                   const ContactSet& set, const ColliderFrame& collider, Real h) {
  const std::array<Index, 3> corner{contact.vertices[0], contact.vertices[1], contact.vertices[2]};
  Vec3 normal = Vec3::Zero();
  const Real depth = pushFaceOut(set.cores[contact.core], contact.normal, collider.end.pose, corner,
                                 space.inverseMass, space.x, space.v, 0, normal);
  m_pushed[index] += depth;
  if (depth > 0) {
    for (Index i : corner) moved(i);
  }
  if (!m_frictionOn || !contact.resting || !(contact.friction > 0)) return depth;
  // Friction at the face's centroid over the corners that are not on the body themselves (those
  // take it as vertex contacts), with the body's normal where the face touches it.
  const Real thickness = space.owners[space.owner[corner[0]]].thickness;
  const FaceCore& core = set.cores[contact.core];
  if (normal.isZero()) {
    // A face that was not pushed and lies wholly beyond the touching distance takes none (the
    // test below, for its friction point); told apart cheaply before the body is queried.
    std::array<Vec3, 3> local;
    for (int j = 0; j < 3; ++j) local[j] = collider.end.pose.toLocal(space.x[corner[j]]);
    const Real touching = core.reach + (1 + kOnSurfaceShell) * thickness;
    if (faceFartherThan(core, contact.normal, local[0], local[1], local[2], touching)) return depth;
  }
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
  Vec3 lifted = Vec3::Zero();
  for (int j = 0; j < 3; ++j) lifted += b[j] * (space.x[corner[j]] - m_solved[corner[j]]);
  const Real budget = h * contact.solveImpulse + std::max<Real>(0, normal.dot(lifted));
  Vec3 slip = Vec3::Zero();
  for (int j = 0; j < 3; ++j) slip += b[j] * (space.x[corner[j]] - collider.carry(space.startX[corner[j]]));
  slip -= slip.dot(normal) * normal;
  Vec3 applied = m_friction[index];
  applied -= applied.dot(normal) * normal;
  const Vec3 correction = frictionCorrection(slip, applied, budget, contact.friction);
  const Vec3 change = correction - applied;
  for (int j = 0; j < 3; ++j) {
    space.x[corner[j]] += (b[j] * space.inverseMass[corner[j]] / weight) * change;
    moved(corner[j], b[j] != 0 && change != Vec3::Zero());
  }
  m_friction[index] = correction;
  return std::max(depth, frictionViolation(change.norm()));
}

Real ContactProjector::projectPair(ContactSpace& space, std::size_t index, const Contact& contact,
                                   Real h) {
  const auto [inverseMass, weight] = m_pairMass[index];
  if (!(weight > 0)) return 0;
  const Real shortfall = contact.separation - contact.normal.dot(contact.relativePosition(space.x));
  // Moves the pair's sides relative to each other by `relativeChange`.
  const auto move = [&](const Vec3& relativeChange) {
    const Vec3 lambda = relativeChange / weight;
    for (int k = 0; k < 4; ++k) {
      const Index i = contact.vertices[k];
      if (space.inverseMass[i] == 0) continue;
      const Vec3 shift = (contact.weights[k] * inverseMass) * lambda;
      space.x[i] += shift;
      moved(i, shift != Vec3::Zero());
    }
  };
  if (shortfall > 0) {
    move(shortfall * contact.normal);
    m_pushed[index] += shortfall;
  }
  // Friction acts only while the pair touches (the projection holds it at its separation).
  if (!m_frictionOn || !(contact.friction > 0) ||
      !(shortfall > -kOnSurfaceShell * contact.separation)) {
    return std::max<Real>(0, shortfall);
  }
  // The budget: how far the projection has moved the pair apart along its normal in all, plus
  // h times the solve's push (its self-contact penalty).
  Vec3 apart = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    const Index i = contact.vertices[k];
    apart += contact.weights[k] * (space.x[i] - m_solved[i]);
  }
  const Real budget = h * contact.solveImpulse + std::max<Real>(0, contact.normal.dot(apart));
  if (!(budget > 0) && m_friction[index].isZero()) return std::max<Real>(0, shortfall);
  // The relative tangential displacement of the two sides over the substep.
  Vec3 slip = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    const Index i = contact.vertices[k];
    slip += contact.weights[k] * (space.x[i] - space.startX[i]);
  }
  slip -= slip.dot(contact.normal) * contact.normal;
  const Vec3 correction =
      frictionCorrection(slip, m_friction[index], budget, contact.friction);
  const Real slipped = (correction - m_friction[index]).norm();
  move(correction - m_friction[index]);
  m_friction[index] = correction;
  return std::max({Real(0), shortfall, frictionViolation(slipped)});
}

Index ContactProjector::finish(ContactSpace& space, const ContactSet& set,
                               std::span<const ColliderFrame> colliders,
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
        kept = coulombFriction(tangential, contact.solveImpulse + removed, contact.friction);
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
      const auto [inverseMass, weight] = m_pairMass[c];
      if (!(weight > 0)) continue;
      const Vec3 gap = contact.relativePosition(space.x);
      if (contact.normal.dot(gap) > (1 + kOnSurfaceShell) * contact.separation) continue;
      const Real normalSpeed = contact.relativePosition(space.v).dot(contact.normal);
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
