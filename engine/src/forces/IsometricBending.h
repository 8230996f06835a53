// Isometric bending: a bending energy that is quadratic in the positions, in the spirit of
// Bergou, Wardetzky, Harmon, Zorin & Grinspun, "A Quadratic Bending Model for Inextensible
// Surfaces", SGP 2006: for isometric deformations of a flat sheet, curvature is a linear function
// of the positions, so the energy has a constant Hessian.
//
// Why not the dihedral hinge (BaraffWitkin.h, kept as BendingModel::Dihedral): its weight
// 3 l²/(A_A + A_B) is right only when curvature is shared evenly by the three edge directions. On
// the regular grid (quads split along one diagonal) a cylinder bent about the warp or the weft
// costs 2.3–3× the continuum energy, one bent about the split diagonal ≈ 9×. Bergou's per-edge
// quadratic form approximates the same hinge energy and inherits that.
//
// Why not Bergou's vertex form D/2 Σ_v |Δx|² A_v (cotangent Laplacian): |Δx|² = (κ₁ + κ₂)²
// is a plate with Poisson ratio 1. Saddles (κ₂ = −κ₁) cost nothing, and in the small-deflection
// limit the membrane does not resist them either: a 3-vertex-wide cantilever strip comes out at
// 0.53 D. Cloth has a Poisson ratio near 0 and D is measured on strips (ASTM D1388).
//
// Energy: the plate with Poisson ratio 0, W = D/2 |∇²x|² = D/2 Σ_ab |∂_a ∂_b x|² over the rest
// (material) coordinates. For an isometric deformation of a flat sheet ∂_a∂_b x = II_ab n exactly
// (the metric is flat), so W = D/2 (κ₁² + κ₂²): D/2 κ² for a cylinder bent in any direction, and a
// saddle costs as much as two cylinders. The Hessian at vertex v is its average over the
// barycentric cell (divergence theorem, P1 gradients G_t per triangle):
//
//     A_v ∂_a∂_b x ≈ −Σ_t A_t ∂_aφ_v G_t[b] + Σ_(free edges e at v) (l_e / 2) n_e,a G_t(e)[b]
//
// which is a fixed linear combination S(x) = Σ_j w_j x_j of v and its one ring. The closed cell
// makes it exactly zero for any affine x, at free edges too, so rigid motions cost nothing; its
// trace is the cotangent Laplacian. Three stencils per vertex (H_uu, H_vv, symmetrised H_uv):
//
//     E = D/2 Σ_s c_s |S_s(x) − α_s n_v(x)|²,   c = 1/A_v, 1/A_v, 2/A_v
//
// Accuracy on a 41 × 41 grid (cylinders of curvature 3/m): interior energy within 0.1 % of
// D/2 κ² A in every direction; the whole sheet 2.6 % low when bent across two of its edges (the
// cell of a free-edge vertex does not see curvature across the edge, where the bending moment of a
// free edge vanishes anyway), 0.2 % off along the diagonal. On a cantilever the vertex at the
// clamp edge sees half the curvature of its cell: an O(h) softening (0.92 D at 24 elements, 0.96 D
// at 48).
//
// For a flat rest shape (α = 0) E is quadratic with the constant Hessian D Σ_s c_s w_s w_sᵀ ⊗ I₃:
// positive semi-definite, nothing to drop in StiffnessMode::Definite, nothing to recompute.
// It couples vertices two rings apart: 19 blocks per matrix row on the grid, against 13 with
// hinges. Rejected for that reason alone: the cotangent Laplacian (13 blocks, see above).
//
// Rest shape. A stencil's rest value S(x̄) splits into a tangential part and α n̄ along the rest
// vertex normal. Flat rest shapes have neither. For curved ones the tangential part is removed by
// adjusting the weights (the least-squares smallest correction that makes S(x̄) normal), which
// keeps E quadratic and rigid-motion invariant; the normal part α is subtracted along the current
// area-weighted vertex normal n_v(x), which is lagged in the derivatives (force and Hessian treat
// it as constant). E is then zero at rest and under any rigid motion and exact for flat rest
// shapes; for curved ones the force misses α (S − α n)ᵀ ∂n/∂x, which vanishes at rest. Strongly
// curved garments are better served by BendingModel::Dihedral. Vertices next to non-manifold
// edges get no stencil, nor do corners holding a single triangle (their cell sees no curvature).
//
// Damping k_d acts on S(v) with the same constant matrix (Rayleigh damping of the bending
// modes). It conserves linear momentum but, unlike condition damping, not exactly angular
// momentum: a rigid spin ω of bent cloth has S(v) = ω × S(x) ≠ 0 and is damped in proportion to
// k_d |S(x)|. With the curtain's k_d/D ≈ 2 ms that is negligible next to air drag.
#pragma once

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>

#include <span>
#include <vector>

namespace weft {

/// Everything ClothModel stores for the isometric bending energy.
struct BendingStencils {
  std::vector<BendingStencil> stencils;  ///< three per vertex that has a bending term
  std::vector<StencilWeight> weights;    ///< all stencils' weights, centre vertex first
  std::vector<Index> triangles;          ///< incident triangles of curved-rest stencils
};

/// Builds the stencils of a mesh from its rest positions and triangles. `edges` as in ClothModel,
/// where triangles[1] == kInvalidIndex marks a boundary edge and kInvalidIndex − 1 an edge shared
/// by more than two triangles. Vertices on such edges, and those in `skipped` (bowties: fans
/// that meet at a point transmit no bending), get no stencil.
BendingStencils buildBendingStencils(const Vec3Array& restPositions,
                                     const std::vector<Index>& indices,
                                     const std::vector<Edge>& edges,
                                     const std::vector<Index>& skipped = {});

/// S(x) = Σ_j w_j x_j over the stencil's weights (the centre's included), in m.
Vec3 stencilVector(const BendingStencil& stencil, std::span<const StencilWeight> weights,
                   const Vec3Array& x);

/// Unit area-weighted normal of the stencil's triangles at positions x (zero if they have no
/// area). `indices` are the mesh's three indices per triangle.
Vec3 stencilNormal(const BendingStencil& stencil, std::span<const Index> triangles,
                   const std::vector<Index>& indices, const Vec3Array& x);

/// The stencil's residual S(x) − α n_v(x), in m: zero at rest and under rigid motions.
Vec3 bendingResidual(const BendingStencil& stencil, std::span<const StencilWeight> weights,
                     std::span<const Index> triangles, const std::vector<Index>& indices,
                     const Vec3Array& x);

}  // namespace weft
