// ContactProjector: one projection that satisfies, together, the strain limit of every edge and
// every contact of the substep (separation and Coulomb friction), with pinned vertices immovable.
//
// Method. After the implicit solve, the end positions x are projected onto the constraints by
// Gauss–Seidel (Provot 1995 for the edges; Bridson, Fedkiw & Anderson 2002 for the contacts,
// whose corrections are the same projection; Müller et al. 2020, "Detailed rigid body simulation
// with extended position based dynamics", for friction at the position level):
//  - edge e = (a, b): |x_b − x_a| ≤ (1 + limit) L, corrected along the edge in inverse proportion
//    to mass (momentum kept, only pins take force); in the first sweep, where neither end touches
//    anything, only the end farther from the pins moves ("follow the leader",
//    ContactSpace::anchorDistance), which brings a long or heavily loaded hanging chain within its
//    limit in one pass, where shared corrections would diffuse edge by edge;
//    an end resting on a collider is moved only across the surface's normal, so the edges slide
//    it on the body instead of pulling it in for the contact to push out again;
//  - vertex–collider: the signed distance to the body (posed at the substep end) ≥ thickness,
//    re-evaluated at the vertex's current position, the vertex followed from where it was last
//    outside (a vertex an edge pulls across a thin body goes back to its own side);
//  - face–collider: every face point keeps its reach from the core (FaceCores.h);
//  - vertex–face, edge–edge: n · Σ w_k x_k ≥ thickness with the detected n and w; inside a pair
//    every movable vertex counts as heavy as the pair's heaviest, so that a light sheet under a
//    heavy body does not take almost all of every correction (it would give it back to its edges
//    on the next sweep and converge at m_light / m_heavy per iteration).
// An edge left within its limit whose ends have not moved since (each vertex counts its moves)
// is skipped, which changes nothing (its correction would be none): the late sweeps, where a few
// edges are still converging, measure only the edges near them. Once at most half the edges are
// left to visit (tried from the fourth sweep), a sweep walks the set of them (VisitSet) that the
// moves keep up to date, instead of testing every edge: the same visits in the same order, at a
// cost that follows the edges still converging, not the cloth. A contact whose last visit moved
// none of its vertices is skipped alike until one of them moves.
// Every position change Δx is made as the velocity change Δx / h too, so v stays the substep's
// average velocity. Sweeps alternate direction; the iteration stops when no edge is over its
// limit by more than the tolerance and no contact is violated by more than its tolerance, a
// change of its friction counting as a violation only in the first sweeps (below).
//
// Friction. A contact's friction may remove at most μ D of the tangential displacement of its two
// sides over the substep, D being its normal displacement: how far the projection has moved its
// sides apart along its normal, plus h times the solve's contact impulse for a collider contact
// (the solve carries a resting cloth's weight and the projection then pushes nothing) and for a
// pair within one cloth (its penalty in the solve holds the layers, SelfContactPenalty.h). A contact
// that rests at the substep start takes it on its whole tangential displacement relative to the
// body, so that it sticks without creeping h² a a substep; one that met the body within the
// substep takes it on its velocity instead (its end is where its path slid on from the hit, not
// x₀ + h v). Friction acts in every sweep, its accumulated correction bounded by that budget, so
// the later sweeps' strain and separation corrections cannot undo what it holds, and a cloth
// pulled over a body at its limit still slides once its budget is spent. Where other contacts
// keep moving a pair apart by a few µm a sweep (a folded hem in self-contact), its budget moves
// with them and its friction follows for hundreds of sweeps without settling; after
// kFrictionCountedSweeps (16) only separations and strain decide when the iteration stops,
// friction acting in every sweep still.
//
// After the iteration: collider contacts and pairs keep no relative normal velocity into each
// other (inelastic), and the face points left resting on a core are returned as supports, which
// the next solve holds (ContactDetector::constrain).
//
// Rejected: a global solve of the constraints (a PCG on J W Jᵀ λ over the active set), which on a
// pinned triangle mesh met more active edges than free degrees of freedom and diverged; projecting
// the constraint kinds one after another in separate passes, which fight where they meet (sheets
// pressed between two bodies and into each other).
#pragma once

#include "contact/ColliderFrame.h"
#include "contact/ContactSet.h"
#include "contact/ContactDetector.h"
#include "contact/ContactSpace.h"
#include "contact/VisitSet.h"

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace weft {

/// How hard the projector tries.
struct ProjectionSettings {
  /// Strain an edge may stay above its limit when the iteration stops.
  Real strainTolerance = 1e-3;
  /// Fraction of a contact's thickness it may stay violated when the iteration stops.
  Real contactTolerance = 1e-2;
  /// Gauss–Seidel sweeps at most; the report says what was left.
  int maxIterations = 256;
};

/// What one projection did.
struct ProjectionReport {
  int iterations = 0;        ///< sweeps run (0: nothing to correct)
  Index edgesOverLimit = 0;  ///< edges over limit + tolerance when it stopped
  /// Contacts short of their separation by more than a tenth of their thickness when it stopped
  /// at its sweep cap (0 when it converged).
  Index contactsViolated = 0;
  Index colliderContacts = 0;  ///< vertices and faces on a collider at the end
};

class ContactProjector {
 public:
  /// Projects space.x (and v) onto the edges' limits and the contacts of `set`, for a substep of
  /// length h from space.startX; writes the resting face points into `supports`.
  ProjectionReport project(ContactSpace& space, const ContactSet& set,
                           std::span<const ColliderFrame> colliders, Real h,
                           const ProjectionSettings& settings, std::vector<FaceSupport>& supports);

 private:
  // One Gauss–Seidel sweep over the edges over their limit; returns how many were over
  // limit + tolerance before their correction.
  Index sweepEdges(ContactSpace& space, Real tolerance, bool backward);
  template <bool tracking>
  Index sweepEdgesAs(ContactSpace& space, Real tolerance, bool backward);
  // The contacts of `set` short of their separation by more than `shortfall` thicknesses,
  // measured without correcting.
  Index unseparatedContacts(const ContactSpace& space, const ContactSet& set,
                            std::span<const ColliderFrame> colliders, Real shortfall) const;
  // Σ m_moves over the contact's vertices.
  std::uint64_t movesOf(const Contact& contact) const;
  // Marks edge e (at sweep position `slot`) as seen within its limit when it is (sweepEdges skips
  // it until an end moves).
  void markIfWithin(const ContactSpace& space, Index e, Index slot);
  // Counts a move of `vertex` and, once tracking, puts its edges and its tether back into the edge
  // sweeps (a vertex moved again and again lists them once, until one of them settles).
  void moved(Index vertex, bool did = true) {
    m_moves[vertex] += did;
    if (did && m_trackingEdges && !m_edgesPending[vertex]) listEdgesOf(vertex);
  }
  void listEdgesOf(Index vertex);
  // Takes the edge at sweep position `slot`, between vertices a and b, off the pending edges.
  void settle(Index slot, Index a, Index b);
  // From the next sweep on, the edge sweeps visit only the pending edges, if few enough are.
  void startTracking(const ContactSpace& space);
  // One sweep over the contacts; returns how many were violated beyond tolerance.
  Index sweepContacts(ContactSpace& space, const ContactSet& set,
                      std::span<const ColliderFrame> colliders, Real h, Real tolerance,
                      bool backward);
  Real projectVertex(ContactSpace& space, std::size_t index, const Contact& contact,
                     const ColliderFrame& collider, Real h);
  Real projectFace(ContactSpace& space, std::size_t index, const Contact& contact,
                   const ContactSet& set, const ColliderFrame& collider, Real h);
  Real projectPair(ContactSpace& space, std::size_t index, const Contact& contact, Real h);
  // The final velocity pass and the supports (see the file comment).
  Index finish(ContactSpace& space, const ContactSet& set, std::span<const ColliderFrame> colliders,
               std::vector<FaceSupport>& supports);

  // Per contact of the set being projected.
  std::vector<Real> m_pushed;     // m, normal displacement the projection gave it
  Vec3Array m_friction;           // m, the friction correction in place
  Vec3Array m_lastOutside;        // vertex contacts: where the vertex last was outside
  std::vector<std::pair<Real, Real>> m_pairMass;  // pairs: pairInverseMass, fixed in a projection
  bool m_frictionOn = true;       // friction acts in this sweep
  bool m_frictionCounted = true;  // a change of friction alone counts as a violation this sweep
  // How much a friction change of `change` (m) counts towards a contact's violation this sweep.
  Real frictionViolation(Real change) const { return m_frictionCounted ? change : 0; }
  bool m_followTheLeader = true;  // edges move only their end farther from the pins
  std::vector<char> m_visited;    // visited in an earlier sweep (a vertex contact's path tested)
  // Per contact: its vertices' m_moves after a visit that moved none of them (sweepContacts
  // skips it until one moves); max when none.
  std::vector<std::uint64_t> m_contactSeenMoves;
  std::vector<char> m_touching;   // per vertex: in a contact of the set
  std::vector<std::uint8_t> m_colliderContactsOf;  // per vertex: its vertex–collider contacts, 2 meaning more
  std::vector<std::uint32_t> m_moves;  // per vertex: how many times the projection moved it
  std::vector<std::uint64_t> m_edgeSeenMoves;  // per edge: its ends' m_moves after its last visit
  // The edges (by sweep position) the next edge sweeps must visit: those not seen within their
  // limit since an end last moved. Visiting only these is the same sweep as visiting all.
  VisitSet m_pendingEdges;
  // The vertices whose tether the next edge sweep must test: those moved since it was within.
  VisitSet m_pendingTethers;
  Index m_tethered = 0;              // vertices with a tether entry (ContactSpace::tetherAnchor)
  bool m_trackingEdges = false;      // the edge sweeps walk the pending sets, or every edge
  // Per vertex: every edge of it is in m_pendingEdges, and it is in m_pendingTethers.
  std::vector<char> m_edgesPending;
  std::span<const Index> m_edgeSlotBegin, m_edgeSlots;  // the space's (ContactSpace::edgeSlots)
  Vec3Array m_surfaceNormal;      // per vertex: the collider surface it rests on, zero if none
  Vec3Array m_solved;             // the positions the projection started from (the solve's)
};

}  // namespace weft
