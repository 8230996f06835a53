// FrameCostModel: the frame-budget planner. It fits the cost of a frame to what earlier frames
// measured and picks the plan (substeps, PCG tolerance, iteration cap) predicted to fit a budget.
//
// Design note. The model is deliberately small, with one number per kind of work, because it is
// refitted every frame from a handful of timings and must follow load changes (self-contact
// starting, other programs taking the cores) within a few frames:
//
//     frame ms ≈ substeps · (c_substep + solvesPerSubstep · c_iteration · iterations(τ, cap))
//     iterations(τ, cap) = min(cap, k · log10(1/τ))
//
// c_substep (ms of everything but the PCG per substep: assembly, collisions, bookkeeping),
// c_iteration (ms per PCG iteration) and k (iterations per decade of residual reduction) are
// exponential averages of the measured values. k is fitted only from converged solves: a capped
// solve says how many iterations it was allowed, not how many it needed.
//
// Planning relaxes accuracy in the order that costs least: the tolerance first (decade by decade,
// up to StepBudget::loosestCgTolerance), then the iteration cap, then, for implicit cloths only,
// the substeps. Before anything is measured the cloths' own settings run. Collision handling is
// not a knob: it always runs in full.
#pragma once

#include <weft/engine/StepBudget.h>
#include <weft/engine/StepStats.h>

namespace weft {

/// What the planner needs to know about the world's cloths for this frame.
struct PlanDefaults {
  Index substeps = 1;       ///< largest substep count the cloths would take on their own
  Real cgTolerance = 1e-3;  ///< tightest tolerance among the cloths
  int cgMaxIterations = 200;  ///< largest cap among the cloths
  bool allImplicit = true;  ///< every awake cloth uses ImplicitEuler (substeps may be reduced)
};

class FrameCostModel {
 public:
  /// Plan for the next frame. With no measurement yet, or when the defaults are predicted to fit,
  /// the plan is empty (every field 0: the cloths' own settings).
  StepPlan plan(const StepBudget& budget, const PlanDefaults& defaults) const;

  /// Predicted ms of a frame running (substeps, tolerance, cap); infinity before any measurement.
  Real predictMs(Index substeps, Real tolerance, int cap) const;

  /// Refits from a frame that ran `totalSubsteps` substeps (summed over cloths) at tolerance
  /// `tolerance`. `smoothing` in (0, 1] is the weight of this frame.
  void record(const StepStats& stats, Index totalSubsteps, Real tolerance, Real smoothing);

  bool measured() const { return m_measured; }
  Real msPerSubstep() const { return m_msPerSubstep; }
  Real msPerIteration() const { return m_msPerIteration; }
  Real iterationsPerDecade() const { return m_iterationsPerDecade; }

 private:
  bool m_measured = false;
  Real m_msPerSubstep = 0;
  Real m_msPerIteration = 0;
  Real m_solvesPerSubstep = 1;
  Real m_iterationsPerDecade = 0;
};

}  // namespace weft
