#include "FrameCostModel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

Real decades(Real tolerance) { return std::max<Real>(0, -std::log10(tolerance)); }

Real blend(Real old, Real fresh, Real weight, bool first) {
  return first ? fresh : (1 - weight) * old + weight * fresh;
}

}  // namespace

Real FrameCostModel::predictMs(Index substeps, Real tolerance, int cap) const {
  if (!m_measured) return std::numeric_limits<Real>::infinity();
  const Real iterations = std::min<Real>(cap, m_iterationsPerDecade * decades(tolerance));
  return Real(substeps) *
         (m_msPerSubstep + m_solvesPerSubstep * m_msPerIteration * iterations);
}

StepPlan FrameCostModel::plan(const StepBudget& budget, const PlanDefaults& defaults) const {
  StepPlan plan;
  if (!m_measured || budget.milliseconds <= 0) return plan;
  const Real target = budget.headroom * budget.milliseconds;
  Index substeps = defaults.substeps;
  Real tolerance = defaults.cgTolerance;
  int cap = defaults.cgMaxIterations;
  if (predictMs(substeps, tolerance, cap) <= target) return plan;

  // 1. Looser tolerance, a decade at a time.
  const Real loosest = std::max(budget.loosestCgTolerance, defaults.cgTolerance);
  while (tolerance < loosest && predictMs(substeps, tolerance, cap) > target) {
    tolerance = std::min(loosest, tolerance * 10);
  }
  // 2. Fewer iterations: the cap that fills what the substeps leave of the target.
  auto capFor = [&](Index n) {
    const Real perIteration = m_solvesPerSubstep * m_msPerIteration;
    const Real room = target / Real(n) - m_msPerSubstep;
    Real fitting = perIteration > 0 ? std::floor(room / perIteration) : Real(cap);
    if (!std::isfinite(fitting)) fitting = Real(cap);
    return int(std::clamp<Real>(fitting, std::max(1, budget.fewestCgIterations), cap));
  };
  if (predictMs(substeps, tolerance, cap) > target) cap = capFor(substeps);
  // 3. Fewer implicit substeps (each one longer), when even that does not fit.
  if (defaults.allImplicit && predictMs(substeps, tolerance, cap) > target) {
    const Index fewest = std::clamp<Index>(budget.fewestSubsteps, 1, defaults.substeps);
    while (substeps > fewest && predictMs(substeps, tolerance, cap) > target) --substeps;
    cap = std::max(cap, capFor(substeps));
    cap = std::min(cap, defaults.cgMaxIterations);
  }
  plan.substeps = substeps;
  plan.cgTolerance = tolerance;
  plan.cgMaxIterations = cap;
  return plan;
}

void FrameCostModel::record(const StepStats& stats, Index totalSubsteps, Real tolerance,
                            Real smoothing) {
  if (totalSubsteps == 0) return;  // every cloth slept: nothing measured
  const bool first = !m_measured;
  const Real substeps = Real(totalSubsteps);
  m_msPerSubstep =
      blend(m_msPerSubstep, std::max<Real>(0, stats.stepMs - stats.solveMs) / substeps, smoothing, first);
  m_solvesPerSubstep = blend(m_solvesPerSubstep, Real(stats.linearSolves) / substeps, smoothing, first);
  if (stats.cgIterations > 0) {
    m_msPerIteration = blend(m_msPerIteration, stats.solveMs / stats.cgIterations, smoothing,
                             first || m_msPerIteration == 0);
  }
  if (stats.linearSolves > 0 && !hasFlag(stats.status, StepStatus::SolverNotConverged) &&
      decades(tolerance) > 0) {
    const Real perDecade = Real(stats.cgIterations) / stats.linearSolves / decades(tolerance);
    m_iterationsPerDecade = blend(m_iterationsPerDecade, perDecade, smoothing, first);
  } else if (hasFlag(stats.status, StepStatus::SolverNotConverged) && stats.linearSolves > 0) {
    // A capped solve needed at least what it ran.
    const Real perDecade = Real(stats.cgIterations) / stats.linearSolves / std::max<Real>(decades(tolerance), 1);
    m_iterationsPerDecade = std::max(m_iterationsPerDecade, perDecade);
  }
  m_measured = true;
}

}  // namespace weft
