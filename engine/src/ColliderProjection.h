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
//    thickness along the surface normal there (the projection of ColliderResponse's last step);
//  - a face point short of its reach from a core is moved back to it
//    (ColliderFaceContacts::project, the pairs its last resolve() found).
// The faces are projected before the vertices, which keep the last word as in Cloth's passes.
// Every position change Δx is made as the velocity change Δx / h too, as the limiter does.
// So one iteration of the limiter runs the edges, the self-contacts it holds and the colliders,
// and it stops only when none of them needs correcting (or at its iteration cap).
//
// Which vertices: those within `thickness + margin` of a collider when the round starts
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
  /// Sets up the constraints of one limiter run: `colliders` (posed at the end of the step; the
  /// span must stay valid until the run ends), the face contacts of their last resolve() with the
  /// same colliders (null: vertices only) over `triangles`, 1/m per vertex (0 for pins, which
  /// are not constrained), the contact thickness (m) and how far (m) from a collider's surface a
  /// vertex at `x` may be and still be constrained in this run.
  void prepare(std::span<const ColliderFrame> colliders, const ColliderFaceContacts* faces,
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
  std::span<const ColliderFrame> m_colliders;
  const ColliderFaceContacts* m_faces = nullptr;
  std::span<const TriangleRest> m_triangles;
  std::span<const Real> m_inverseMasses;
  Real m_thickness = 0;
  std::vector<VertexContact> m_vertexContacts;  // in vertex order, then collider order
  std::vector<Aabb> m_boxes;                    // per collider: its box inflated by the reach
};

}  // namespace weft
