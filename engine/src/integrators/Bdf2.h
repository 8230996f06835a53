// BDF2: the second-order backward differentiation formula, linearised as Baraff & Witkin's
// backward Euler is, and solved by the same filtered PCG (Choi & Ko, "Stable but Responsive
// Cloth", SIGGRAPH 2002, §3, use it for cloth).
//
// With the step ratio ω = h_n / h_{n−1} (variable-step BDF2, e.g. Hairer & Wanner, Solving ODEs
// II, §III.5), a = (1 + ω)²/(1 + 2ω), b = ω²/(1 + 2ω) = a − 1 and β = (1 + ω)/(1 + 2ω):
//      x_{n+1} = a x_n − b x_{n−1} + βh v_{n+1}
//      v_{n+1} = a v_n − b v_{n−1} + βh M⁻¹ f(x_{n+1}, v_{n+1})
// (ω = 1: a = 4/3, b = 1/3, β = 2/3). That is ImplicitEuler's step with the offsets
// x̂ − x_n = b (x_n − x_{n−1}), v̂ − v_n = b (v_n − v_{n−1}) and η = βh (ImplicitEuler.h), so pins,
// contact constraints, self-contact couplings, Newton iterations and the warm start all work as
// there. A-stable, but unlike backward Euler it damps an undamped mode only at fourth order in
// ωh, so cloth keeps its swing at large steps.
//
// The history (x_{n−1}, v_{n−1}) is the state the previous step started from, after whatever the
// collision and strain passes did to it, so the formula always reads the states the cloth really
// had. The first step, a step after reset() (a teleport, a restore without history, a retried
// frame), a step that does not follow on in time from the last one (a cloth woken from sleep) and
// a step more than kMaxStepRatio times the previous one are backward-Euler steps, which start the
// history again. Rejected: TR-BDF2, which is one-step (no history to restart) but takes two
// solves per step, a trapezoidal stage and a BDF2 stage, for the same order.
#pragma once

#include "integrators/ImplicitEuler.h"

namespace weft {

class Bdf2 final : public Integrator {
 public:
  explicit Bdf2(const SolverSettings& settings) : m_implicit(settings) {}

  /// Largest h_n / h_{n−1} stepped with BDF2; variable-step BDF2 is zero-stable below 1 + √2.
  static constexpr Real kMaxStepRatio = 2;

  IntegratorKind kind() const override { return IntegratorKind::Bdf2; }
  int order() const override { return 2; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;
  void setSolveLimits(Real tolerance, int maxIterations) override {
    m_implicit.setSolveLimits(tolerance, maxIterations);
  }
  void setSolveAccuracy(Real tolerance, PcgStopping stopping) override {
    m_implicit.setSolveAccuracy(tolerance, stopping);
  }
  void reset() override;
  /// The warm start and the history, so a restored world continues bit for bit.
  void saveCarriedState(Vec3Array& out) const override;
  std::size_t carriedStateCapacity(std::size_t vertexCount) const override;
  void restoreCarriedState(const Vec3Array& in) override;
  /// Carries the warm start and, for a translation, the history with the motion (the next step
  /// goes on as if nothing happened); a turn forgets the history (gravity does not turn with
  /// the cloth), so that teleport's next step is a backward-Euler step.
  void carryCarriedState(const RigidFit& motion) override;

 private:
  ImplicitEuler m_implicit;
  Vec3Array m_previousPosition;  // x_{n−1}: m, the state the last step started from
  Vec3Array m_previousVelocity;  // v_{n−1}: m/s
  Vec3Array m_positionOffset;    // b (x_n − x_{n−1}), m
  Vec3Array m_velocityOffset;    // b (v_n − v_{n−1}), m/s
  Real m_previousStep = 0;       // s, h_{n−1}
  Real m_nextTime = 0;           // s, the time the last step ended at
  bool m_hasHistory = false;
};

}  // namespace weft
