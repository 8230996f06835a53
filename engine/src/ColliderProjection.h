// ColliderProjection: the collider contacts of a cloth as position constraints that the strain
// limiter in contact projects onto together with its edges and self-contacts.
//
// Design note
// -----------
// Why: after the implicit solve, Cloth ran the strain limiter, the collider passes (vertices,
// then faces: ColliderResponse, ColliderFaceContacts) and the self-collision pass one after the
// other, a few rounds. Each pass satisfies its own constraints and breaks the others', and where
// they conflict — three sheets pressed between a sphere and a ring of 2 cm capsules, stress
// scene 7 — the rounds do not converge: edges stayed stretched to strain 0.79 (4.7 with the
// layers shifted by 1e-5 m) and faces ended 1–2 cm inside a capsule. The limiter held the
// vertices the collider pass had put on a surface along its normal (two-sided, fixed on two
// surfaces), which keeps it from pulling them in but also from moving them off, so an edge
// anchored at both ends on the ring could not be shortened at all.
//
// What: the collider contacts as one-sided constraints of the limiter's Gauss–Seidel iteration
// (StrainLimiter::applyInContact's PositionConstraints), evaluated at the current positions
// every iteration, the body infinitely heavy:
//  - a vertex within `thickness` of a collider (posed at the end of the step) is put on the
//    thickness; followed along its path from where the last projection left it (keepOutside with
//    the body held still), so that a vertex an edge pulled across a thin body goes back to its
//    side instead of out through the far one;
//  - a face point short of its reach from a core is moved back to it
//    (ColliderFaceContacts::project, the pairs its last resolve() found).
// The faces are projected before the vertices, which keep the last word as in Cloth's passes.
// Every position change Δx is made as the velocity change Δx / h too, as the limiter does.
// So one iteration of the limiter runs the edges, the self-contacts and the colliders, and it
// stops only when none of them needs correcting (or at its iteration cap).
//
// How Cloth uses it (ClothSettings::jointContactProjection, limitStrainInContact, in a substep
// whose first collider pass found contacts and whose first self-collision pass found
// self-contacts; with collider contacts alone the sequential rounds converge and, holding the
// vertices along the surfaces, keep a resting cloth still): no vertex is held along a surface
// normal (the edges may lift it off); every
// self-contact that any self-collision pass of the substep found is held at the separation that
// pass left it at; after each projection the collider passes run from where it left the
// vertices (not from the step start: the chord from there to a vertex carried round a body can
// cut the body) and the self-collision pass runs; rounds of 256 iterations until one finds
// nothing to correct, 24 at most, then a last projection, followed only by the collider passes.
// Measured (stress scene 7, README row 7): each of these was needed for 0.101 and no crossing.
// Known limit: the last projection can carry pairs that were not in contact past each other if
// the rounds left much to correct (2 … 10 crossing pairs after 6 rounds of 64 iterations at
// 16 × 16 vertices a layer, 4 in one of four draws after 12 rounds of 256); after 24 rounds of
// 256 none was seen.
//
// Which vertices: those within `thickness + margin` of a collider when the run starts
// (prepare()); one iteration moves a vertex far less than the margin (Cloth: half an edge), and
// the collider passes after the limiter still catch everything.
#pragma once

#include "ColliderFaceContacts.h"
#include "ColliderResponse.h"
#include "StrainLimiting.h"

#include <weft/Math.h>
#include <weft/collision/Aabb.h>
#include <weft/engine/ClothModel.h>

#include <span>
#include <vector>

namespace weft {

/// Vertex and face collider contacts as one-sided position constraints (see the design note).
class ColliderProjection final : public PositionConstraints {
 public:
  /// Sets up the constraints of one limiter run: the vertices against `colliders` (posed at the
  /// end of the step), the faces as the last resolve() of `faces` (null: vertices only) found
  /// them against `faceColliders`, the colliders that resolve() was given, over `triangles`
  /// (both spans must stay valid until the run ends); 1/m per vertex (0 for pins, which are not
  /// constrained), the contact thickness (m) and how far (m) from a collider's surface a vertex
  /// at `x` may be and still be constrained in this run.
  void prepare(std::span<const ColliderFrame> colliders, const ColliderFaceContacts* faces,
               std::span<const ColliderFrame> faceColliders,
               std::span<const TriangleRest> triangles, std::span<const Real> inverseMasses,
               Real thickness, Real margin, std::span<const Vec3> x);

  /// Faces, then vertices, out of the colliders at x (see the design note); returns how many
  /// were deeper than a hundredth of the thickness.
  Index project(std::span<Vec3> x, std::span<Vec3> v, Real inverseStep) override;

 private:
  struct VertexContact {
    Index vertex = 0;
    Index collider = 0;  // into m_colliders
    Vec3 lastOutside = Vec3::Zero();  // where the vertex was after the last projection
  };
  std::span<const ColliderFrame> m_colliders, m_faceColliders;
  const ColliderFaceContacts* m_faces = nullptr;
  std::span<const TriangleRest> m_triangles;
  std::span<const Real> m_inverseMasses;
  Real m_thickness = 0;
  std::vector<VertexContact> m_vertexContacts;  // in vertex order, then collider order
  std::vector<Aabb> m_boxes;                    // per collider: its box inflated by the reach
};

}  // namespace weft
