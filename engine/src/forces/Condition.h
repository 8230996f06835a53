// Condition: the Baraff–Witkin formalism that every cloth force kernel shares.
//
// Baraff & Witkin, "Large Steps in Cloth Simulation", SIGGRAPH 1998, §4 and §5: an element
// (triangle, hinge, spring) is described by one scalar condition C(x) over its 2–4 vertices,
// which is zero in the rest state. With stiffness k and damping k_d
//
//     energy        E  = k/2 · C²
//     elastic force f  = −k C ∇C
//     damping force d  = −k_d Ċ ∇C,        Ċ = ∇C · v
//
// and the implicit solver needs the Jacobians of f + d. Exactly,
//
//     ∂(f+d)/∂x = −k (∇C ∇Cᵀ + C ∇²C) − k_d (Ċ ∇²C + ∇C (∇²C v)ᵀ)      (last term non-symmetric)
//     ∂(f+d)/∂v = −k_d ∇C ∇Cᵀ
//
// Kernels (BaraffWitkin.h, SpringCondition.h) only produce C, ∇C and, when asked, ∇²C as fixed-size
// Eigen objects; accumulateConditionForces() turns them into energy, forces and Jacobians. Keeping
// that step in one place means every element type gets the same stiffness treatment.
//
// Two stiffness modes, because the backward-Euler system A = M − h ∂f/∂v − h² ∂f/∂x must stay
// symmetric positive definite for (filtered) conjugate gradients:
//
//   Exact     the true derivative above. Used by the finite-difference tests and by anyone who
//             wants a Newton step; A can be indefinite and non-symmetric with it.
//   Definite  what the implicit solver uses, in the spirit of Choi & Ko 2002 ("Stable but
//             Responsive Cloth"):
//               keep    −k ∇C ∇Cᵀ                        (always negative semi-definite)
//               keep    −k C ∇²C  only when the condition is convex (∇²C ⪰ 0 by construction:
//                                 stretch, spring) and C ≥ 0 (stretched), where it is ⪯ 0
//               drop    −k C ∇²C  for compressed or non-convex conditions (shear, bend), whose
//                                 sign flips with C and the geometry; under compression it is
//                                 what makes cloth buckle violently in an implicit step
//               drop    both damping position terms (non-symmetric, and only first order in v;
//                                 Baraff & Witkin §5.2 drop them too)
//             The velocity Jacobian is kept exact: −k_d ∇C ∇Cᵀ is already ⪯ 0.
//             Then −∂f/∂x ⪰ 0 and −∂f/∂v ⪰ 0, so A is SPD for any h > 0 and positive masses.
//   Rejected: projecting each element Hessian onto the PSD cone with a 12×12 eigen-decomposition.
//   It keeps more of the curvature but costs an eigen-solve per hinge per substep; the rule above is
//   free and is what the cited cloth literature does.
#pragma once

#include <weft/Math.h>

#include <Eigen/Core>

namespace weft {

/// One scalar condition C(x) over VertexCount vertices, with its gradient and (when asked) Hessian.
/// Degrees of freedom are ordered x0.x, x0.y, x0.z, x1.x, …
template <int VertexCount>
struct Condition {
  static constexpr int kVertexCount = VertexCount;  ///< vertices the condition depends on
  static constexpr int kDofs = 3 * VertexCount;     ///< position components it depends on
  using Gradient = Eigen::Matrix<Real, kDofs, 1>;
  using Hessian = Eigen::Matrix<Real, kDofs, kDofs>;

  Real value = 0;                          ///< C(x), in the unit the stiffness is paired with
  Gradient gradient = Gradient::Zero();    ///< ∂C/∂x
  Hessian hessian = Hessian::Zero();       ///< ∂²C/∂x², filled only when the kernel was asked
  /// ∂²C/∂x² is positive semi-definite by construction (stretch, spring); then C·∂²C is PSD
  /// whenever C ≥ 0, which StiffnessMode::Definite relies on.
  bool convex = false;
};

/// How accumulateConditionForces() forms the position Jacobian (see the design note above).
enum class StiffnessMode {
  Exact,     ///< the true ∂f/∂x, possibly indefinite and non-symmetric (tests, Newton)
  Definite,  ///< symmetric negative semi-definite ∂f/∂x for the implicit solver
};

/// Energy, force and Jacobians of one element over N vertices, accumulated from its conditions.
template <int N>
struct ElementForces {
  static constexpr int kDofs = 3 * N;  ///< position components of the element
  using Vector = Eigen::Matrix<Real, kDofs, 1>;
  using Matrix = Eigen::Matrix<Real, kDofs, kDofs>;

  Real energy = 0;                             ///< J, elastic potential k/2 C² summed
  Vector force = Vector::Zero();               ///< N, elastic + damping force on each vertex
  Matrix positionJacobian = Matrix::Zero();    ///< N/m, ∂force/∂x
  Matrix velocityJacobian = Matrix::Zero();    ///< N·s/m, ∂force/∂v

  /// Clears everything, so one ElementForces can be reused across elements without allocation.
  void setZero() {
    energy = 0;
    force.setZero();
    positionJacobian.setZero();
    velocityJacobian.setZero();
  }
};

/// Adds the condition's elastic (stiffness k) and damping (k_d) contribution into `out`: energy
/// and force always, and both Jacobians when `withJacobians`. The Jacobians need the condition's
/// Hessian: compute the condition with withHessian = true whenever withJacobians is true.
/// `velocities` are the element's vertex velocities in the condition's dof order.
template <int N>
void accumulateConditionForces(const Condition<N>& condition, Real stiffness, Real damping,
                               const Eigen::Matrix<Real, 3 * N, 1>& velocities,
                               StiffnessMode mode, bool withJacobians, ElementForces<N>& out) {
  const auto& gradient = condition.gradient;
  const Real value = condition.value;
  const Real valueRate = gradient.dot(velocities);  // Ċ = ∇C · v

  // Damping dissipates and stores nothing, so only the elastic part enters the energy.
  out.energy += Real(0.5) * stiffness * value * value;
  // f + d = −(k C + k_d Ċ) ∇C: both act along the same gradient.
  const Real forceScale = stiffness * value + damping * valueRate;
  out.force.noalias() -= forceScale * gradient;
  if (!withJacobians) {
    return;
  }

  const typename Condition<N>::Hessian outer = gradient * gradient.transpose();
  out.positionJacobian.noalias() -= stiffness * outer;
  if (damping != 0) out.velocityJacobian.noalias() -= damping * outer;  // exact: 0·outer adds +0

  if (mode == StiffnessMode::Exact) {
    // −k C ∇²C − k_d Ċ ∇²C share the Hessian; the last term is ∂Ċ/∂x = ∇²C v along ∇C.
    out.positionJacobian.noalias() -= forceScale * condition.hessian;
    out.positionJacobian.noalias() -=
        (damping * gradient) * (condition.hessian * velocities).transpose();
  } else if (condition.convex && value > 0) {
    // Stretched convex condition: C ∇²C ⪰ 0, so keeping it preserves definiteness and the
    // geometric stiffness that makes a taut cloth respond quickly sideways.
    out.positionJacobian.noalias() -= (stiffness * value) * condition.hessian;
  }
}

}  // namespace weft
