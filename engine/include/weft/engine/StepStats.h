// What a World::step() did: status flags that name the knob to turn, and per-frame statistics.
#pragma once

#include <weft/Math.h>
#include <weft/engine/StepBudget.h>

#include <cstdint>
#include <string>

namespace weft {

/// Bit flags returned by World::step(). Ok (0) means nothing to report.
enum class StepStatus : std::uint32_t {
  Ok = 0,
  /// An explicit integrator needed more substeps than SolverSettings::maxSubsteps to stay stable,
  /// or the motion diverged: raise maxSubsteps, lower stiffness, or use ImplicitEuler.
  Unstable = 1u << 0,
  /// A PCG solve stopped at cgMaxIterations before cgTolerance: raise cgMaxIterations or
  /// cgTolerance, or take smaller steps.
  SolverNotConverged = 1u << 1,
  /// The frame failed even with 8× the substeps; the cloth was restored to its state before the
  /// frame (it did not move this frame).
  RolledBack = 1u << 2,
  /// The step was refused (bad frameDt); nothing changed.
  InvalidInput = 1u << 3,
  /// A frame went non-finite or diverged and was redone with more substeps (up to 8×); see
  /// StepStats::substeps. Lower the stiffness or the frame length if it keeps happening.
  RetriedWithSmallerStep = 1u << 4,
  /// step() took longer than StepBudget::milliseconds. The plan it ran is in StepStats::plan;
  /// the next frames' plans adapt (looser PCG tolerance, fewer iterations, fewer implicit
  /// substeps) within the limits of StepBudget. Raise the budget or those limits if it persists.
  BudgetMissed = 1u << 5,
  /// A cloth ended the frame stretched past its ClothMaterial::strainLimit by more than
  /// kStrainLimitSlack (see StepStats::clothsOverStrainLimit, maxStrain): its pins, contacts or
  /// loads demand more than the limit, or the limiter ran out of iterations. Take more
  /// substeps, move pins less far per frame, or raise the limit.
  StrainLimitExceeded = 1u << 6,
  /// Two colliders closed on a cloth to less than twice its ClothMaterial::thickness: the
  /// vertices between them were kept midway, closer than the thickness to both, never inside
  /// either (see StepStats::squeezedVertices). Open the gap or thin the cloth.
  Squeezed = 1u << 7,
  /// The impact pass's impulses and impact zones did not clear every crossing within their
  /// passes, and its last resort held the rest's vertices at their substep start (see
  /// StepStats::frozenVertices): nothing crossed, but those vertices stopped. Take more substeps
  /// or raise the thickness if it persists.
  ContactsFrozen = 1u << 8,
  /// The contact projection stopped at its sweep cap with contacts still short of their
  /// separation by more than a tenth of their thickness (StepStats::unresolvedContacts): nothing
  /// crossed (the impact pass has the last word), but those features ended the substep that much
  /// nearer each other or a body. Take more substeps, or move pins and bodies less far per frame.
  ContactsUnresolved = 1u << 9,
};

constexpr StepStatus operator|(StepStatus a, StepStatus b) {
  return StepStatus(std::uint32_t(a) | std::uint32_t(b));
}
constexpr StepStatus& operator|=(StepStatus& a, StepStatus b) { return a = a | b; }
/// True when `flags` holds `flag`.
constexpr bool hasFlag(StepStatus flags, StepStatus flag) {
  return (std::uint32_t(flags) & std::uint32_t(flag)) != 0;
}
/// "ok", or the set flags joined by '|', e.g. "unstable|solver-not-converged".
std::string describe(StepStatus status);

/// Which health check a frame failed (StepStats::healthFailure): the cause behind
/// RetriedWithSmallerStep and RolledBack. Checked after every substep (finite, speed) and at the
/// end of every attempt at a frame (strain, energy); the thresholds sit far above any physical
/// motion, so only a diverging integration trips them.
enum class HealthFailure : std::uint8_t {
  None = 0,
  NonFinite,   ///< a position or velocity became NaN or infinite
  Speed,       ///< a vertex moved faster than kMaxSpeed (10⁴ m/s, InputLimits.h)
  Strain,      ///< an edge grew to more than 100× its rest length, longer than at the frame start
  EnergyJump,  ///< kinetic energy rose 100× above what the frame's own sources could supply
  OutOfRange,  ///< a vertex went beyond kMaxSimulatedCoordinate (1e9 m, InputLimits.h)
};
/// "none", "non-finite", "speed", "strain", "energy-jump" or "out-of-range".
const char* describe(HealthFailure failure);

/// Statistics of the last frame, summed over cloths and substeps (Box2D b2Profile in spirit).
struct StepStats {
  std::uint64_t frame = 0;     ///< frames stepped so far, this one included
  Real simulatedTime = 0;      ///< s, world time at the end of the frame
  Real stepMs = 0;             ///< ms of wall-clock time in step()
  Real assemblyMs = 0;         ///< ms evaluating forces and assembling systems (all substeps)
  Real solveMs = 0;            ///< ms in PCG solves (all substeps)
  Index substeps = 0;          ///< substeps taken (largest over cloths)
  int linearSolves = 0;        ///< PCG solves
  int cgIterations = 0;        ///< PCG iterations summed over solves
  Real cgResidual = 0;         ///< relative residual of the last solve
  /// Largest stretch l / l_rest − 1 over mesh edges at the end (compression, which cloth turns
  /// into folds, does not count).
  Real maxStrain = 0;
  Real kineticEnergy = 0;      ///< J at the end of the frame
  /// J (elastic + gravity) at the start of the last substep; a sleeping cloth, which has not
  /// moved since, counts the value of its last stepped frame.
  Real potentialEnergy = 0;
  Real maxSpeed = 0;           ///< m/s, fastest vertex at the end
  Index contacts = 0;          ///< cloth vertices touching a collider at the end
  /// Contacts of a cloth face with a collider that had passed between its vertices (detected
  /// in every substep, summed)
  Index faceContacts = 0;
  Index selfContacts = 0;      ///< contact pairs within one cloth (all substeps)
  Index selfImpacts = 0;       ///< swept cloth collisions resolved by impulses (all substeps)
  Index impactZones = 0;       ///< rigid impact-zone passes, the fail-safe (all substeps)
  /// Vertices the impact pass's last resort held at their step start because impulses and
  /// impact zones did not clear their contacts (all substeps): the contacts the engine did not
  /// resolve physically. They never cross; they stop instead (StepStatus::ContactsFrozen).
  Index frozenVertices = 0;
  /// Contacts the projection left short of their separation by more than a tenth of their
  /// thickness when it stopped at its sweep cap, summed over substeps
  /// (StepStatus::ContactsUnresolved).
  Index unresolvedContacts = 0;
  /// Sweeps of the contact projection (strain limits and contacts together), summed over
  /// substeps; 0 when no edge went over its limit and no contact was violated.
  int strainLimitIterations = 0;
  /// Edges the projection left over their limit at its sweep cap, summed over substeps (edges
  /// with both ends pinned not counted). The impact pass after it may stretch edges a little
  /// more: maxStrain is what the frame ended with.
  Index strainLimitEdgesOver = 0;
  /// Cloths that ended the frame past their strain limit + kStrainLimitSlack
  /// (StepStatus::StrainLimitExceeded).
  Index clothsOverStrainLimit = 0;
  /// Times the frame was redone with twice the substeps because a cloth ended it past its strain
  /// limit (SolverSettings::strainRetrySubsteps); `substeps` is what the kept attempt took.
  Index strainRetries = 0;
  /// Vertices kept midway between two colliders closer than twice their thickness, summed over
  /// substeps (StepStatus::Squeezed).
  Index squeezedVertices = 0;

  // Frame budget (World::step(frameDt, budget) and World::step(frameDt, plan)).
  Real budgetMs = 0;           ///< ms, the budget this frame was given (0 = none)
  /// What this frame ran: substeps, PCG tolerance and iteration cap. Feeding it back through
  /// World::step(frameDt, plan) from the same state reproduces the frame bit for bit.
  StepPlan plan;

  // Stages a scene did not need (WorldSettings::skipUnneededStages), summed over cloths and
  // substeps. Each pair counts the times the stage ran and the times it was skipped.
  Index colliderNarrowPhases = 0;  ///< cloth–collider pairs tested (constraint and response passes)
  Index colliderNarrowPhasesSkipped = 0;  ///< pairs skipped: the collider's box is not near the cloth's
  Index selfCollisionPasses = 0;   ///< cloth-pair detections run (BVH refit, queries, response)
  /// Passes skipped because the cloth provably cannot touch itself in that substep (fold culling:
  /// no fold, and features farther apart than the thickness plus twice the step's motion). A
  /// cloth with ClothSettings::selfCollision off counts neither run nor skipped passes.
  Index selfCollisionSkipped = 0;
  Index bendingAssemblies = 0;     ///< force evaluations that included the bending hinges
  Index dampingJacobians = 0;      ///< assemblies that formed damping (∂f/∂v) Jacobians
  Index sleepingCloths = 0;        ///< cloths asleep during this frame (not stepped)
  Index wokenCloths = 0;           ///< cloths that woke at the start of this frame
  /// Cloths carried with their pins' jump this frame (SolverSettings::pinTeleportDistance).
  Index teleportedCloths = 0;
  StepStatus status = StepStatus::Ok;  ///< the flags step() returned
  Index clothContacts = 0;     ///< contact pairs between different cloths (all substeps)
  /// The check the last failed attempt at this frame tripped (None when no attempt failed): why
  /// the frame was retried or rolled back. With several cloths, the first cloth that failed.
  HealthFailure healthFailure = HealthFailure::None;
  /// Scalar unknowns of the implicit solve, summed over cloths (each cloth's last solve of the
  /// frame): 3 per free vertex, since pinned vertices are removed from the system
  /// (SolverSettings::removePinnedVertices); 3 per vertex when they are kept. 0 without a solve.
  Index solvedUnknowns = 0;
  /// Self-collision BVH nodes whose boxes were recomputed (all refits of all substeps).
  Index bvhNodesRefit = 0;
  /// BVH nodes kept because their triangles moved less than a margin since their last refit
  /// (WorldSettings::skipUnneededStages; the collision results are the same bits either way).
  Index bvhNodesSkipped = 0;
};

}  // namespace weft
