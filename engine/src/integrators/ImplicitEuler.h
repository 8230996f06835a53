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
// Pins: a pinned vertex's velocity change is known, Δv_p = (x_target(t + h) − x_n)/h − v_n, so it
// lands exactly on its target whatever drift came before (for a pin moving at constant velocity
// within a frame Δv_p is zero after the frame's first substep; it is the pin's change of velocity
// otherwise). When the system removes pinned vertices (DynamicSystem::freeVertexMap()) the solve
// runs over the free rows only, A_ff Δv_f = b_f − A_fp Δv_p; pinned vertices that keep a row are
// filtered instead (BW98 §5.3: S = 0, target Δv_p), which solves the same equations. Contacts are
// always filtered. Self-contacts (DynamicSystem::contactCouplings, ContactCoupling.h) are rank-one
// terms the system adds to A outside its pattern; the PCG applies them matrix-free, and a removed
// pin in one contributes its known Δv to the right-hand side. Warm start: the PCG begins from the previous step's Δv, which is close in smooth
// motion.
//
// Two-step methods (Bdf2.h) reuse this step through ImplicitStepHistory: with a step scale β and
// the history's offsets x̂ = x_n + positionOffset, v̂ = v_n + velocityOffset, the step solves
//      x_{n+1} = x̂ + βh v_{n+1},      M (v_{n+1} − v̂) = βh f(x_{n+1}, v_{n+1}).
// With η = βh and u = v_n + (x̂ − x_n)/η, so that x_{n+1} − x_n = η (u + Δv), the same expansion
// about (x_n, v_n) gives the same matrix with η for h:
//      (M − η ∂f/∂v − η² ∂f/∂x) Δv = η (f_n + η ∂f/∂x u) + M (v̂ − v_n)
// and a Newton iteration solves (…)|_k δ = η f(x_k, v_k) − M (Δv_k − (v̂ − v_n)) with
// x_k = x̂ + η v_k. Backward Euler is β = 1 without offsets (x̂ = x_n, v̂ = v_n, u = v_n): the
// equations above, and the same bits.
#pragma once

#include "integrators/Integrator.h"
#include "solver/FilteredPcg.h"
#include "solver/VertexFilter.h"

#include <span>
#include <vector>

namespace weft {

/// The history a two-step implicit method adds to the step (see the note above): backward Euler
/// when beta = 1 and both offsets are null.
struct ImplicitStepHistory {
  Real beta = 1;                              ///< step scale β: the step solves with η = βh
  const Vec3Array* positionOffset = nullptr;  ///< m by vertex, x̂ − x_n; null = none
  const Vec3Array* velocityOffset = nullptr;  ///< m/s by vertex, v̂ − v_n; null = none
};

class ImplicitEuler final : public Integrator {
 public:
  explicit ImplicitEuler(const SolverSettings& settings) : m_settings(settings) {}

  IntegratorKind kind() const override { return IntegratorKind::ImplicitEuler; }
  int order() const override { return 1; }
  void step(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
            IntegratorReport& report) override;
  /// The step of a two-step method whose history is `history` (Bdf2); step() is this with
  /// ImplicitStepHistory{}.
  void stepWithHistory(DynamicSystem& system, Vec3Array& x, Vec3Array& v, Real t, Real h,
                       const ImplicitStepHistory& history, IntegratorReport& report);
  void reset() override;
  void setSolveLimits(Real tolerance, int maxIterations) override {
    m_settings.cgTolerance = tolerance;
    m_settings.cgMaxIterations = maxIterations;
  }
  void setSolveAccuracy(Real tolerance, PcgStopping stopping) override {
    m_settings.cgTolerance = tolerance;
    m_settings.cgStopping = stopping;
  }
  void saveCarriedState(Vec3Array& out) const override;
  std::size_t carriedStateCapacity(std::size_t vertexCount) const override { return vertexCount; }
  /// The warm start the next step takes (m/s per vertex; empty: none), what saveCarriedState()
  /// writes, without a copy.
  std::span<const Vec3> warmStart() const {
    return m_hasWarmStart ? std::span<const Vec3>(m_deltaV) : std::span<const Vec3>();
  }
  void restoreCarriedState(const Vec3Array& in) override;
  void carryCarriedState(const RigidFit& motion) override;

 private:
  void resizeVertices(Index vertexCount);
  void resizeRows(Index rowCount);
  // On a cloth with no pin and no contact constraint: the rigid velocity change (x the step's
  // start positions) that takes the net force and torque out of the PCG's residual, so an
  // inexact solve keeps the momentum and angular momentum its forces give (internal: none).
  void keepMomentum(const DynamicSystem& system, const FreeVertexMap& map, const Vec3Array& x);
  void solve(DynamicSystem& system, IntegratorReport& report);
  // The system's active contact couplings renumbered into rows (m_rowCouplings), their forces
  // added to the row right-hand side (h (F + h K v), or h F for a Newton iteration; h is the
  // step's η) and, with
  // removedPins, their coupling to removed pins' known Δv (m_deltaV) taken to it.
  void gatherCouplings(const DynamicSystem& system, const FreeVertexMap& map, bool removedPins,
                       Real h, bool newton);
  // Sets each coupling active when its normal force at the end of the step, in the solve's
  // linear model, pushes (h F_end = impulse − coefficient · J Δv > 0, Δv = m_deltaV by vertex);
  // true when the active set changed.
  bool updateActiveCouplings(const DynamicSystem& system, Real h);
  // The impulse (A Δv − b)·p of each contact-constrained row after the solve, into
  // m_contactImpulse (zero for the other rows), for DynamicSystem::receiveContactImpulses.
  void measureContactImpulses(const DynamicSystem& system);

  SolverSettings m_settings;
  FilteredPcg m_pcg;
  VertexFilter m_filter;                  // by system row
  std::vector<Index> m_filteredRows;      // rows of pins set fixed in m_filter last step
  FreeVertexMap m_identityMap;            // for systems that remove nothing (freeVertexMap() null)
  Vec3Array m_deltaV;            // Δv of this step by vertex; the previous one is the warm start
  Vec3Array m_correction;        // by row: the solve's unknown (Δv, or δ of a Newton iteration)
  std::vector<Real> m_rowMass;   // by row: the vertex masses (kg), for the PCG's stopping norm
  Vec3Array m_rowRightHandSide;  // by row: b gathered, minus the removed pins' coupling
  Vec3Array m_force;             // f at the expansion point
  Vec3Array m_stiffnessTimesVelocity;
  Vec3Array m_rightHandSide;     // b by vertex
  Vec3Array m_iteratePosition;   // x_k
  Vec3Array m_iterateVelocity;   // v_k
  Vec3Array m_expansionVelocity;  // u = v_n + (x̂ − x_n)/η of a two-step method's step
  Vec3Array m_prescribedPosition, m_prescribedVelocity;
  std::vector<ContactCoupling> m_rowCouplings;  // the system's active contact couplings, by row
  std::vector<char> m_couplingActive;           // per system coupling: 1 while it pushes
  std::vector<Real> m_contactImpulse;  // by row: N·s along the contact constraint, 0 if none
  bool m_hasWarmStart = false;
};

}  // namespace weft
