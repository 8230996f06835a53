// SelfContactPenalty: a cloth's self-contacts as terms of its implicit solve.
//
// Why. The projection after the solve (ContactProjector) keeps the layers of a fold or a pile
// apart, but a solve that does not see them moves every vertex towards the equilibrium of the
// cloth alone, through the layer under it; the projection then stops only the vertices in
// contact, and the velocity it gives back (Δx / h) leaves their neighbours' share of the solve's
// push. A jammed pile so trades the energy of its elastic stress against the contacts' push every
// substep and never comes to rest. Baraff & Witkin 1998 (§6) hold cloth–cloth contact in the
// solve with stiff springs; so does this: each pair of the last substep's ContactSet within one
// cloth is a penalty ½ k (d₀ − d)² of the implicit step (ContactCoupling.h), one-sided through
// ImplicitEuler's active set, with k = SolverSettings::selfContactStiffness × the cloth's stretch
// stiffness (at 1 a pair pressed a thickness deep pushes as hard as an edge stretched by its
// thickness). The projection and the impact pass still have the last word. It is an option, off
// by default: terms that stiff couple layers the PCG's preconditioner does not see, and cost
// about 2.5× the CG iterations in the frames with contact (the curtain's sphere phase); softer
// terms (0.1, 0.3) leave some piles stirring as the projection alone does.
//
// Friction. A pair the solve holds apart is pushed by its penalty, not by the projection, so the
// velocity change the penalty gave at the end of the step, k (d₀ − d(x₁)) h Σ w_k² / m_k, is the
// pair's share of friction's bound (ContactProjector), as the constraint impulse is a collider
// contact's: layers held by the solve grip each other by the cloth's friction.
//
// The pairs. The features (vertex–face, edge–edge) of the last substep's pairs are kept with the
// cloth, so they are part of its saved state; at the start of a substep their closest points,
// weights and normal are taken again at the start positions, which are free of crossings, so a
// pair's side is the one its points are on now. A pair farther apart than the pairs' reach is no
// term. A cloth without self-contacts has no features and pays nothing. A pair with a pinned
// vertex is no term either: the solve cannot move the pinned side, so the whole push lands on the
// free one, and a sheet crushed onto its own pinned row (pins dragged and stopped) stays hooked
// over it; the projection holds such pairs with the pinned side immovable.
//
// Rejected: the pairs as filter constraints of the solve (a vertex's normal velocity fixed),
// which fixes a layer's absolute motion where only the relative one is known; a proximity query
// of its own at the substep start, which costs a broad phase per substep where the detection's
// pairs of the last substep are the same pairs but for those that just came within reach.
#pragma once

#include "contact/ContactDetector.h"
#include "contact/ContactSet.h"

#include <weft/Math.h>

#include <array>
#include <optional>
#include <span>

namespace weft {

/// The features of one self-contact pair of a cloth (its vertex indices), as detected.
struct SelfContactFeatures {
  ContactKind kind = ContactKind::VertexFace;  ///< VertexFace or EdgeEdge
  std::array<Index, 4> vertices{};             ///< (p; a, b, c) or (p₀, p₁; q₀, q₁)
  Vec3 normal = Vec3::Zero();  ///< as detected: orients a pair whose points coincide
};

/// A pair at given positions: Σ w_k x_k is the first side minus the second, n points from the
/// second side to the first, and d = n · Σ w_k x_k is its gap (m).
struct SelfContactPair {
  ContactKind kind = ContactKind::VertexFace;
  std::array<Index, 4> vertices{};
  std::array<Real, 4> weights{};
  Vec3 normal = Vec3::Zero();
  Real gap = 0;
  /// m/s, the change of the pair's normal relative velocity its penalty gave in the solve (set
  /// after the solve): the friction bound of the pair's contact, as a collider contact's
  /// Contact::solveImpulse.
  Real solveImpulse = 0;
};

/// Orders pairs by kind, then vertices: the key a detected contact finds its solve pair by.
inline bool selfContactBefore(ContactKind kindA, const std::array<Index, 4>& verticesA,
                              ContactKind kindB, const std::array<Index, 4>& verticesB) {
  if (kindA != kindB) return kindA < kindB;
  return verticesA < verticesB;
}

/// m: the gap the penalty of a pair `startGap` apart at the substep start keeps: the thickness, or
/// for a pair closer than that the repulsion rate's share of the way back to it, as the
/// projection asks (a sandwiched layer pressed tighter than two thicknesses cannot be pushed to
/// both at once; a spring that insisted would pump the energy of the fold every substep).
inline Real penaltyRestGap(Real startGap, Real thickness) {
  return startGap < thickness ? startGap + kRepulsionRate * (thickness - startGap) : thickness;
}

/// The pair of `features` at positions `x` (closest points), or nothing when its gap is `reach`
/// (m) or more or the pair is degenerate. A pure kernel.
std::optional<SelfContactPair> selfContactAt(const SelfContactFeatures& features,
                                             std::span<const Vec3> x, Real reach);

}  // namespace weft
