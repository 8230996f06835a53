// StepBudget and StepPlan: what a caller allows World::step() to spend on a frame, and what the
// engine decided to run.
//
// A budgeted step plans before it runs: from the measured cost of earlier frames (ms per substep
// outside the solver, ms per PCG iteration, iterations a solve needs) it picks the substeps, the
// PCG tolerance and the iteration cap that are predicted to fit, relaxing accuracy only as far as
// needed and only within the limits given here. Collision handling is never part of the plan:
// contacts with colliders and with the cloth itself are always resolved, however small the budget.
// The plan is recorded in StepStats::plan; World::step(frameDt, plan) runs a given plan exactly,
// so a replay that feeds the recorded plans back is bitwise reproducible although the planning
// itself depends on the machine's timing.
#pragma once

#include <weft/Math.h>

namespace weft {

/// A frame budget and what the engine may relax to meet it.
struct StepBudget {
  /// ms of wall-clock time one World::step() may take; 0 = no budget (the cloths' own settings).
  Real milliseconds = 0;
  /// The loosest PCG tolerance a plan may use, in the sense of the cloths' cgStopping; a cloth
  /// whose own cgTolerance is looser keeps its own, and hard substeps keep tightCgTolerance.
  /// Default: the default cgTolerance, so a budget meets a small frame with the cap and substeps.
  Real loosestCgTolerance = 1e-1;
  /// PCG iterations per solve a plan never goes below: a solve cut much shorter leaves the step
  /// closer to explicit Euler than to implicit, and can go unstable.
  int fewestCgIterations = 30;
  /// Implicit substeps a plan may drop to per frame (explicit integrators keep their stable
  /// count: dropping substeps would make them blow up, not merely less accurate).
  Index fewestSubsteps = 1;
  /// Weight of the newest frame in the running cost estimates, in (0, 1]; higher follows load
  /// changes faster and noise more.
  Real costSmoothing = 0.3;
  /// Share of the budget the plan aims at, in (0, 1]: the rest absorbs timing noise.
  Real headroom = 0.85;
  /// Safety net: while the last frame's largest strain (StepStats::maxStrain) exceeds this, the
  /// cloths' own settings run whatever the budget, so a relaxed solve cannot feed a blow-up.
  Real strainGuard = 0.3;
};

/// What one frame ran, for every cloth. Zero fields mean "the cloth's own setting".
struct StepPlan {
  Index substeps = 0;       ///< substeps per frame (0: SolverSettings, automatic or fixed)
  Real cgTolerance = 0;     ///< relative PCG tolerance (0: SolverSettings::cgTolerance)
  int cgMaxIterations = 0;  ///< PCG iteration cap per solve (0: SolverSettings::cgMaxIterations)
  /// Same fields.
  friend bool operator==(const StepPlan&, const StepPlan&) = default;
};

}  // namespace weft
