// ContactSet: the one representation of a contact in a substep, whatever touches what.
//
// Every contact is a one-sided constraint on a point of the cloth,
//
//     n · (p − q) ≥ separation,
//
// with p a point of the cloth (a vertex, or a barycentric point of a face or an edge) and q the
// point it must stay away from (a collider's surface, a core inside a collider, or a point of
// another face or edge of the same or another cloth). The four `vertices` and `weights` write
// p − q as Σ w_k x_k, as Bridson, Fedkiw & Anderson 2002 do for their pairs:
//
//     VertexCollider  (v)               w = (1)                 q on the collider's surface
//     FaceCollider    (a, b, c)         w = found per iteration q on a core of the collider
//     VertexFace      (p; a, b, c)      w = (1, −b₀, −b₁, −b₂)  q = 0 (both sides are cloth)
//     EdgeEdge        (p₀, p₁; q₀, q₁)  w = (1 − s, s, −(1 − u), −u)
//
// Detection (ContactDetector) fills a ContactSet once per substep; the implicit solve reads the
// collider contacts as constraints and writes back their impulses (the friction bound); the
// projector (ContactProjector) enforces every contact with the strain limit; the impact pass
// (ImpactResolver) has the last word with its swept tests.
#pragma once

#include "contact/FaceCores.h"

#include <weft/Math.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace weft {

/// What a contact holds apart.
enum class ContactKind : std::uint8_t {
  VertexCollider,  ///< a cloth vertex and a collider's surface
  FaceCollider,    ///< a cloth face and a core of a collider (a body thinner than the triangles)
  VertexFace,      ///< a cloth vertex and a cloth face (same or another cloth)
  EdgeEdge,        ///< two cloth edges (same or another cloth)
};

/// One contact of a substep (see the file comment).
struct Contact {
  ContactKind kind = ContactKind::VertexCollider;
  /// Vertices of the contact space (kInvalidIndex for unused slots).
  std::array<Index, 4> vertices{kInvalidIndex, kInvalidIndex, kInvalidIndex, kInvalidIndex};
  /// p − q = Σ weights[k] · x[vertices[k]] (pairs; a vertex contact has (1, 0, 0, 0)).
  std::array<Real, 4> weights{1, 0, 0, 0};
  /// Unit normal at detection, from q towards p: the side p must stay on.
  Vec3 normal = Vec3::Zero();
  /// m, the distance the contact keeps along the normal (thickness, or a core's reach).
  Real separation = 0;
  /// m, the distance along the normal when detected (at the end of the solved motion; pairs: the
  /// smaller of start and end).
  Real gap = 0;
  /// Coulomb coefficient of the two sides.
  Real friction = 0;
  /// Collider kinds: index into the substep's colliders; FaceCollider also `core` (into the
  /// set's cores), and its `normal` is the core-to-face direction at the substep start in the
  /// body's frame (zero when the face started on the core): the side it must go back to.
  Index collider = kInvalidIndex;
  Index core = kInvalidIndex;
  /// m/s, the normal velocity change the implicit solve gave the contact: a collider contact's
  /// constraint, a pair's self-contact penalty (0 when the solve held neither). Part of the
  /// friction bound.
  Real solveImpulse = 0;
  /// True when the contact began the substep touching (within the contact shell): friction then
  /// acts on the substep's whole tangential displacement, so a resting contact does not creep.
  bool resting = false;

  /// p − q at positions `x` (pairs: all four vertices are set).
  Vec3 relativePosition(std::span<const Vec3> x) const {
    Vec3 sum = Vec3::Zero();
    for (int k = 0; k < 4; ++k) sum += weights[k] * x[vertices[k]];
    return sum;
  }
};

/// Every contact of one substep, in a deterministic order: collider contacts by vertex (then
/// collider), face contacts by face, then the pairs in broad-phase order.
struct ContactSet {
  std::vector<Contact> contacts;
  /// The cores the face contacts refer to (FaceCores.h), in the bodies' frames.
  std::vector<FaceCore> cores;
  /// Index of the first pair contact (VertexFace or EdgeEdge); collider contacts come before.
  std::size_t firstPair = 0;

  void clear() {
    contacts.clear();  // keeps its capacity
    cores.clear();
    firstPair = 0;
  }
  std::size_t size() const { return contacts.size(); }
};

}  // namespace weft
