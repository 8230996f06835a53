// ColliderFaceContacts: keeps the faces of a cloth, not only its vertices, out of round colliders
// (spheres and capsules).
//
// Design note
// -----------
// Why: ColliderResponse keeps every vertex outside every collider (plus the contact thickness),
// but a triangle is more than its corners. Where a body is thinner than the cloth's triangles —
// a capsule of 2 cm radius under edges of 3–5 cm — the body can pass between the vertices
// through a face or an edge while every vertex stays outside. Once through, the cloth hangs on
// the body by that edge, stretched between the vertices on either side. Measured: a 0.5 m
// cotton square of 11 × 11 vertices dropped onto a rod of 2 cm radius fell straight through it
// (ColliderFaceContactsTest), and in stress scene 7 (three sheets pushed through a ring of
// capsules) the worst edges ran straight through a capsule of the ring, one end inside the ring
// and one outside, with a face 2 cm deep (the capsule's core) in 33–44 of the 150 frames.
//
// What: after each collider response pass (Cloth runs the vertex pass once more when faces were
// moved, so that the vertices keep the last word: a corner pushed out of one body can land in
// another), every triangle whose bounding box reaches a sphere or
// capsule is tested against the body's core (the sphere's centre, the capsule's segment) with the
// segment–triangle closest-point kernel (Proximity.h), in the body's frame. A face point deeper
// in the body than the allowance (Cloth passes the contact thickness) is moved out along the
// contact normal to that depth by moving the three corners, each by its barycentric weight b_k
// and inverse mass w_k: Δx_k = b_k w_k / (Σ_j b_j² w_j) · depth · n, which moves the face point
// by exactly depth · n (the impulse distribution of Bridson, Fedkiw & Anderson 2002 for a
// point–triangle contact, with the body infinitely heavy). Why an allowance: the vertices keep
// the thickness outside the body, and a coarse mesh over a curved body sags between them by
// l² / (8 R) (3.8 mm for 5 cm edges on the 8 cm pusher of stress scene 7); pushing those faces
// out would lift the vertices off wherever a coarse mesh lies on a curved body and change
// ordinary draping for nothing, while a face that a thin body passes through is caught long
// before the core. With the thickness as the allowance the curtain has no face contact at all
// (its state hash is unchanged).
// Contacts are resolved one after the other in triangle order (Gauss–Seidel; serial, so the same
// bits on any thread count) and swept again while a sweep still moved a face, a few times at
// most (neighbouring faces share corners). Then, once, each face point's velocity into the body
// (relative to the body's surface there) is removed the same way (inelastic); removed in every
// sweep, the pushes of the successive contacts of one face added up and the face left faster
// than the body (a rod rising at 1.8 m/s into a face sent its corners off at up to 2.5 m/s).
//
// Which side: a face point that reached the core (distance 0) or crossed it within the step has
// no normal of its own, or the wrong one. The normal of the same test at the step start (the
// start positions in the body's start frame) decides then: the face goes back to the side it came
// from, as the vertices' continuous test sends them.
//
// The strain limiter in contact holds each contact one-sided (holds(): n · Σ b_k x_k ≥
// n · c + R − allowance, c the core point), as it holds heavy self-contacts, so that its rounds
// slide the cloth round the body instead of pulling the face back into it (on the rod of the
// test, max strain 0.101 with the holds, 0.103 without).
//
// Not covered: boxes and triangle-mesh colliders (their corners and edges can still poke through
// a face; their faces are flat, so a cloth face cannot pass a flat face between its vertices, and
// a plane never), and a body that passes through a whole face within one step (faster than its
// radius per step relative to the cloth: the vertices' continuous test still catches the corners).
#pragma once

#include "ColliderResponse.h"
#include "StrainLimiting.h"

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>

#include <span>
#include <vector>

namespace weft {

/// What one resolve() did.
struct ColliderFaceReport {
  Index contacts = 0;  ///< face–body contacts found in the first sweep
  Index sweeps = 0;    ///< sweeps over the contacts (the first included)
};

/// Keeps cloth faces out of sphere and capsule colliders (see the design note).
class ColliderFaceContacts {
 public:
  /// Moves faces of `triangles` that are deeper than `allowance` (m) inside a sphere or capsule
  /// of `colliders` out to that depth, and removes their velocity into it. `xStart`: positions at the step start (which
  /// side a face came from). Vertices with inverse mass 0 (pins) are not moved.
  ColliderFaceReport resolve(std::span<const ColliderFrame> colliders,
                             std::span<const TriangleRest> triangles, const Vec3Array& xStart,
                             std::span<const Real> inverseMasses, Real allowance, Vec3Array& x,
                             Vec3Array& v);

  /// The contacts of the last resolve() as one-sided holds for the strain limiter.
  std::span<const SeparationHold> holds() const { return m_holds; }

  /// Forgets the holds (a step without colliders).
  void clear() { m_holds.clear(); }

 private:
  struct Candidate {
    Index triangle = 0;
    Index collider = 0;
    bool touched = false;  // corrected in some sweep of this resolve()
    SeparationHold hold;   // from its last correction
    Vec3 barycentric = Vec3::Zero();  // of the face point at its last correction
  };
  std::vector<Candidate> m_candidates;  // triangles whose box reaches a body, this resolve()
  std::vector<SeparationHold> m_holds;
};

}  // namespace weft
