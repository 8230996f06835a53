// Backward Euler, linearised as in Baraff & Witkin 1998, with optional Newton iterations.
//
// Unknown: the velocity change Δv over the step, with x_{n+1} = x_n + h (v_n + Δv).
//
//  Baraff–Witkin step (always): expand f about (x_n, v_n):
//      (M − h ∂f/∂v − h² ∂f/∂x) Δv = h (f_n + h ∂f/∂x v_n)                       (BW98 eq. 16)
//  Newton iteration k ≥ 1 (SolverSettings::newtonIterations): expand about the current iterate
//  (x_k, v_k) = (x_n + h v_k, v_n + Δv_k) and solve for the correction δ:
//      (M − h ∂f/∂v − h² ∂f/∂x)|_k δ = h f(x_k, v_k) − M Δv_k,      Δv_{k+1} = Δv_k + δ
//  which converges to the exact backward-Euler step M Δv = h f(x_{n+1}, v_{n+1}).
//
// Pins enter through the filter (BW98 §5.3): a pinned vertex gets S = 0 and the target
// Δv = (x_target(t + h) − x_n)/h − v_n, so it lands exactly on its target whatever drift came
// before. Warm start: the PCG begins from the previous step's Δv, which is close in smooth motion.
#pragma once

#include "integrators/Integrator.h"
#include "solver/FilteredPcg.h"
#include "solver/VertexFilter.h"

#include <vector>

namespace weft {

class ImplicitEuler final : public Integrator {
 public:
  explicit ImplicitEuler(const SolverSettings& settings) : m_settings(settings) {}

  IntegratorKind kind() const override { return IntegratorKind::ImplicitEuler; }
  int order() const override { return 1; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;
  void reset() override;
  void setSolveLimits(Real tolerance, int maxIterations) override {
    m_settings.cgTolerance = tolerance;
    m_settings.cgMaxIterations = maxIterations;
  }
  void saveCarriedState(Vec3Array& out) const override;
  void restoreCarriedState(const Vec3Array& in) override;

 private:
  void resize(Index vertexCount);
  void solve(DynamicSystem& system, IntegratorReport& report);

  SolverSettings m_settings;
  FilteredPcg m_pcg;
  VertexFilter m_filter;
  std::vector<Index> m_filteredVertices;  // vertices set fixed in m_filter last step
  Vec3Array m_deltaV;            // Δv of this step; the previous one is the warm start
  Vec3Array m_correction;        // δ of a Newton iteration
  Vec3Array m_force;             // f at the expansion point
  Vec3Array m_stiffnessTimesVelocity;
  Vec3Array m_rightHandSide;     // b
  Vec3Array m_iteratePosition;   // x_k
  Vec3Array m_iterateVelocity;   // v_k
  Vec3Array m_prescribedPosition, m_prescribedVelocity;
  bool m_hasWarmStart = false;
};

}  // namespace weft
