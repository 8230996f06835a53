// Baraff–Witkin cloth conditions: stretch, shear and dihedral bending, with exact derivatives.
//
// Baraff & Witkin, "Large Steps in Cloth Simulation", SIGGRAPH 1998, §4.2–4.3. Each function is a
// pure kernel of a few positions and the element's rest state, returning Condition<N> (Condition.h);
// the loop over the mesh and the assembly live elsewhere.
//
// Stretch and shear (triangle x0, x1, x2 with rest data from makeTriangleRest):
//
//     w_u = Σ warpWeights[i] x_i,  w_v = Σ weftWeights[i] x_i      (BW98 eq. 9)
//     C_warp  = √a (|w_u| − b_u)        C_weft = √a (|w_v| − b_v)       C_shear = √a (w_u · w_v)
//
// BW98 scale by the rest area a; we scale by √a so that E = k/2 C² = k a/2 (|w| − b)²: an energy
// density times area, with k in N/m whatever the mesh resolution.
//
// The implicit step takes the three fused (stretchShear). With the √a-scaled weights a_i, b_i,
// W_u = Σ a_i x_i = √a w_u and d_u = W_u/|W_u|, the corner gradients are a_i d_u, b_i d_v and
// g_i = a_i w_v + b_i w_u, so every per-corner quantity is a_i X_a + b_i X_b of two triangle
// vectors, and the Jacobian block of corners (i, j) is
//
//     a_i a_j X_uu + b_i b_j X_vv + a_i b_j X_uv + b_i a_j X_uvᵀ
//
// with X_uu = h²κ_u I + (h²(k_u − κ_u) + h k_d) d_u d_uᵀ + (h² k_s + h k_ds) w_v w_vᵀ (κ_u = k_u C_u/|W_u|
// while stretched, else 0), X_vv alike and X_uv = (h² k_s + h k_ds) w_v w_uᵀ: three 3×3 matrices
// per triangle instead of three 9×9 Hessians, damping folded into the same blocks.
//
// Bending (hinge x0, x1, x2, x3, drawn as in ClothModel.h):
//
//            x2                 n_A = (x1 − x0) × (x2 − x0)   normal of A = (x0, x1, x2)
//           /  \                n_B = (x3 − x0) × (x1 − x0)   normal of B = (x1, x0, x3), i.e.
//          /  A \                                             wound consistently with A
//        x0 ---- x1   e = x1 − x0
//          \  B /               θ = atan2(ê · (n_B × n_A), n_A · n_B)  ∈ (−π, π]
//           \  /
//            x3
//
// Sign: θ = 0 when flat; θ > 0 when the cloth folds towards A's normal (triangle B rotates about
// the edge into the half-space n_A points to: a valley seen from the n_A side), θ < 0 when it folds
// away (a ridge seen from the n_A side). With the unnormalised normals the atan2 form is robust
// near 0 and ±π, where acos would lose all precision.
//
// C_bend = √scale · wrap(θ − θ_rest) with scale = 3 l²/(A_A + A_B) (hingeStiffnessScale), so that
// E = D/2 · scale · (θ − θ_rest)² approximates the continuum energy D/2 κ² per area with D in N·m.
// The bend gradient and Hessian are exact: derivatives of θ(z) with respect to z = (n_A, n_B, e),
// chained through the bilinear maps z(x) including their constant second derivatives.
//
// Degenerate geometry gives finite values. A stretch fibre collapsed to a point (|w| ≈ 0) has no
// direction; any unit vector is a subgradient of |w| there, and the kernel takes one across the
// other fibre (both collapsed: warp along x, weft along y), the same on every triangle, so that a
// cloth collapsed onto a line or a point is pushed open instead of feeling no stretch force. The
// force lowers the energy whatever the direction (the condition is compressed); its Hessian is
// zero (it is unbounded, and a compressed condition's is not used). Collapsed bend hinges and
// springs give a zero gradient and Hessian: zero is the only choice that cannot inject energy.
#pragma once

#include <forces/Condition.h>
#include <weft/Math.h>
#include <weft/engine/ClothModel.h>

#include <array>

namespace weft {

/// Rest data of a triangle from the material coordinates (u, v) of its vertices, in metres: area
/// = |det|/2 and the weights with w_u = Σ warpWeights[i] x_i, w_v = Σ weftWeights[i] x_i.
/// Precondition: the (u, v) triangle is not degenerate (ClothModel validates its input).
TriangleRest makeTriangleRest(std::array<Index, 3> vertices, const Vec2& uv0, const Vec2& uv1,
                              const Vec2& uv2);

/// The warp (u) and weft (v) stretch conditions of one triangle.
struct StretchConditions {
  Condition<3> warp;  ///< √a (|w_u| − b_u), in m (E = k/2 C², k in N/m)
  Condition<3> weft;  ///< √a (|w_v| − b_v), in m
};

/// Stretch conditions of triangle (x0, x1, x2). The rest scales b_u, b_v are the stretch ratios
/// at rest (1 = unstretched; < 1 pre-tensions the cloth). Hessians filled when `withHessian`.
StretchConditions stretchConditions(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                                    const TriangleRest& rest, Real warpRestScale,
                                    Real weftRestScale, bool withHessian);

/// Shear condition √a (w_u · w_v) of triangle (x0, x1, x2): zero while warp and weft stay
/// orthogonal. Not convex. Hessian filled when `withHessian`.
Condition<3> shearCondition(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                            const TriangleRest& rest, bool withHessian);

/// Rest constants of one triangle's stretch and shear for stretchShear(), precomputed once.
/// The weights carry √a, so W_u = Σ warpWeights[i] x_i = √a w_u is a length.
struct StretchShearRest {
  std::array<Real, 3> warpWeights{};  ///< dimensionless, √a · TriangleRest::warpWeights
  std::array<Real, 3> weftWeights{};  ///< dimensionless, √a · TriangleRest::weftWeights
  Real sqrtArea = 0;                  ///< m, √a
  Real inverseSqrtArea = 0;           ///< 1/m, 1/√a
  Real warpRestLength = 0;            ///< m, √a · b_u: C_warp = |W_u| − warpRestLength
  Real weftRestLength = 0;            ///< m, √a · b_v
};

/// The constants of `rest` for warp and weft rest scales b_u, b_v (see stretchConditions).
StretchShearRest makeStretchShearRest(const TriangleRest& rest, Real warpRestScale,
                                      Real weftRestScale);

/// Stiffness and damping of the three membrane conditions (ClothMaterial's fields).
struct StretchShearCoefficients {
  Real warpStiffness = 0;   ///< N/m
  Real weftStiffness = 0;   ///< N/m
  Real shearStiffness = 0;  ///< N/m
  Real stretchDamping = 0;  ///< N·s/m, on both stretch conditions
  Real shearDamping = 0;    ///< N·s/m
};

/// What one triangle adds to the implicit step (the sum of its warp, weft and shear conditions
/// through accumulateConditionForces in StiffnessMode::Definite, in closed form).
struct StretchShearTerms {
  Real energy = 0;                                  ///< J, elastic k/2 C² summed
  std::array<Vec3, 3> force;                        ///< N per corner, elastic + damping
  std::array<Vec3, 3> stiffnessTimesVelocity;       ///< N/s per corner, (∂f/∂x)·u
  /// kg, X_uu, X_vv, X_uv and X_vu = X_uvᵀ (header): stretchShearBlock() forms the system
  /// blocks −h ∂f/∂v − h² ∂f/∂x from them. X_uu and X_vv are symmetric to the bit.
  Mat3 warpWarp, weftWeft, warpWeft, weftWarp;
};

/// Stretch and shear of triangle x with velocities v: energy and forces always; with
/// `withSystem`, also (∂f/∂x)·u and the system matrices for step h (s). The Jacobians are those
/// of StiffnessMode::Definite (Condition.h): the stretch conditions' curvature only while
/// stretched, the shear's never, damping exact in ∂f/∂v. Collapsed fibres as in stretchConditions.
StretchShearTerms stretchShear(const std::array<Vec3, 3>& x, const std::array<Vec3, 3>& v,
                               const std::array<Vec3, 3>& u, const StretchShearRest& rest,
                               const StretchShearCoefficients& coefficients, Real h,
                               bool withSystem);

/// Adds the triangle's block of corners (i, j) of −h ∂f/∂v − h² ∂f/∂x (kg) to `block`:
/// a_i a_j X_uu + b_i b_j X_vv + (a_i b_j X_uv + b_i a_j X_vu). Block (j, i) comes out as the
/// transpose of block (i, j) to the bit (the bracket sums the same two products), and block (i, i)
/// symmetric, so a matrix assembled from them is symmetric to the bit.
inline void addStretchShearBlock(const StretchShearTerms& terms, const StretchShearRest& rest,
                                 int i, int j, Mat3& block) {
  const Real uu = rest.warpWeights[i] * rest.warpWeights[j];
  const Real vv = rest.weftWeights[i] * rest.weftWeights[j];
  const Real uv = rest.warpWeights[i] * rest.weftWeights[j];
  const Real vu = rest.weftWeights[i] * rest.warpWeights[j];
  const Real* warpWarp = terms.warpWarp.data();
  const Real* weftWeft = terms.weftWeft.data();
  const Real* warpWeft = terms.warpWeft.data();
  const Real* weftWarp = terms.weftWarp.data();
  // Two loops over the nine entries in storage order, the sum into a local first so the compiler
  // sees no aliasing: both vectorise, and nothing is read transposed.
  Real sum[9];
  for (int e = 0; e < 9; ++e) {
    sum[e] = uu * warpWarp[e] + vv * weftWeft[e] + (uv * warpWeft[e] + vu * weftWarp[e]);
  }
  Real* out = block.data();
  for (int e = 0; e < 9; ++e) out[e] += sum[e];
}

/// Signed dihedral angle of the hinge (x0, x1, x2, x3) in (−π, π], rad: 0 when flat, positive
/// when the cloth folds towards the normal of triangle A = (x0, x1, x2). 0 for degenerate input.
Real dihedralAngle(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3);

/// Dimensionless 3 l² / (A_A + A_B) for a hinge of rest length l (m) between triangles of rest
/// areas A_A, A_B (m²); 0 when the areas do not sum to a positive value.
Real hingeStiffnessScale(Real restLength, Real areaA, Real areaB);

/// Bending condition √(hinge.stiffnessScale) · wrap(θ − hinge.restAngle), wrapped into (−π, π],
/// for the hinge (x0, x1, x2, x3) in the order of Hinge::vertices. Exact Hessian when asked.
Condition<4> bendCondition(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& x3,
                           const Hinge& hinge, bool withHessian);

}  // namespace weft
