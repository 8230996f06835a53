// StretchLaw: the tension a woven fabric carries at a given fibre strain, linear or biphasic.
//
// Woven fabric is soft at first and stiff later: under a small load the crimped yarns
// straighten and the crossings flatten (low modulus), then the straight yarns themselves extend
// (a modulus tens of times higher). Kawabata's tensile test (KES-FB1) shows this as a linearity
// LT well below 1, and every woven fabric's load-extension curve in Kawabata & Niwa's and Wang
// et al. 2011's measurements is convex (FabricPresets.cpp cites the numbers). The law here is
// the simplest curve with that shape that stays smooth for the implicit solve: tension per unit
// width T(ε) in N/m at the fibre strain ε = |w| − b (BaraffWitkin.h), with the low-strain
// stiffness k₀ up to the knee ε_k, a tangent stiffness that rises linearly from k₀ to k₁ over
// the next ε_k of strain, and k₁ beyond:
//
//     T(ε) = k₀ ε                                        ε ≤ ε_k (and every compression)
//     T(ε) = k₀ ε + (k₁ − k₀) (ε − ε_k)² / (2 ε_k)        ε_k < ε < 2 ε_k
//     T(ε) = k₀ ε + (k₁ − k₀) (ε − 3 ε_k / 2)             ε ≥ 2 ε_k
//
// so T is C¹ (its tangent T' continuous) and the energy density Ψ = ∫ T dε is C². The energy of
// a triangle's fibre is a Ψ(ε), a its rest area; with C = √a ε (the Baraff–Witkin condition)
//     f = −√a T(ε) ∇C,      ∂f/∂x = −T'(ε) ∇C ∇Cᵀ − √a T(ε) ∇²C,
// which is accumulateConditionForces() with the secant stiffness T/ε on the curvature term and
// the tangent T' on the outer product; below the knee it is that function, bit for bit.
// Rejected: a cubic or exponential law (Ψ ∝ e^{ε/ε₀}): no straight low-strain part to keep the
// fitted k₀ exact, and a stiffness that grows without bound makes the solve's conditioning depend
// on how far a step overshoots.
#pragma once

#include "forces/Condition.h"

#include <weft/engine/Material.h>

#include <cmath>
#include <string>

namespace weft {

/// One fibre direction's law: linear when kneeStrain is 0 or not finite.
struct StretchLaw {
  Real stiffness = 0;          ///< N/m, k₀: the low-strain (crimp) stiffness
  Real kneeStrain = 0;         ///< ε_k: where the stiffness starts to rise; 0 = linear
  Real stiffenedStiffness = 0; ///< N/m, k₁: the tangent stiffness from 2 ε_k on

  /// True when the law has a knee (a positive, finite kneeStrain).
  bool stiffens() const { return kneeStrain > 0 && std::isfinite(kneeStrain); }
};

/// The warp and weft laws of a material (the stiffened values are used only with a knee).
StretchLaw warpStretchLaw(const ClothMaterial& material);
StretchLaw weftStretchLaw(const ClothMaterial& material);

/// What a material's stretch-stiffening fields get wrong, naming the field and the fix; empty
/// when they are valid (a knee of 0 or infinity, or a positive knee with stiffened stiffnesses at
/// least the low-strain ones).
std::string stretchLawProblem(const ClothMaterial& material);

/// Tension and energy at one strain.
struct StretchResponse {
  Real energyDensity = 0;  ///< J/m², Ψ(ε)
  Real tension = 0;        ///< N/m, T(ε) = Ψ'(ε)
  Real tangent = 0;        ///< N/m, T'(ε)
};

/// Ψ, T and T' of the law at the fibre strain ε.
StretchResponse stretchResponse(const StretchLaw& law, Real strain);

/// accumulateConditionForces() for a stretch condition C = √area ε under `law`: the linear law's
/// k/2 C² energy below the knee (the same bits), area Ψ(ε) above it. `area` is the triangle's rest
/// area in m²; the damping acts on the condition rate as for any condition.
template <int N>
void accumulateStretchForces(const Condition<N>& condition, const StretchLaw& law, Real area,
                             Real damping, const Eigen::Matrix<Real, 3 * N, 1>& velocities,
                             StiffnessMode mode, bool withJacobians, ElementForces<N>& out) {
  const Real value = condition.value;
  // Below the knee (C ≤ √a ε_k, compared squared: no square root on the common path).
  if (!law.stiffens() || !(value > 0) || value * value <= area * law.kneeStrain * law.kneeStrain) {
    accumulateConditionForces(condition, law.stiffness, damping, velocities, mode, withJacobians,
                              out);
    return;
  }
  const Real sqrtArea = std::sqrt(area);
  const StretchResponse response = stretchResponse(law, value / sqrtArea);
  const auto& gradient = condition.gradient;
  const Real valueRate = gradient.dot(velocities);
  out.energy += area * response.energyDensity;
  const Real forceScale = sqrtArea * response.tension + damping * valueRate;
  out.force.noalias() -= forceScale * gradient;
  if (!withJacobians) return;
  const typename Condition<N>::Hessian outer = gradient * gradient.transpose();
  out.positionJacobian.noalias() -= response.tangent * outer;
  if (damping != 0) out.velocityJacobian.noalias() -= damping * outer;
  if (mode == StiffnessMode::Exact) {
    out.positionJacobian.noalias() -= forceScale * condition.hessian;
    out.positionJacobian.noalias() -=
        (damping * gradient) * (condition.hessian * velocities).transpose();
  } else if (condition.convex) {
    // Stretched past the knee: T > 0, so √a T ∇²C ⪰ 0 keeps the matrix definite (Condition.h).
    out.positionJacobian.noalias() -= (sqrtArea * response.tension) * condition.hessian;
  }
}

}  // namespace weft
