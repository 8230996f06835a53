// SubstepPipeline: steps every cloth of a world by one frame, all cloths in one contact space,
// each substep one function whose stages read as a list:
//
//   pose       the colliders as values for the substep (shape posed at its end, both motions)
//   constrain  collider contacts of the predicted motion, for the implicit solve
//   solve      each cloth's implicit step (Baraff & Witkin 1998), collider contacts in the
//              filter S, the cloth's self-contacts of the last substep as penalties
//              (contact/SelfContactPenalty.h)
//   detect     one ContactSet of the solved motion: vertex/face × collider, cloth pairs
//   project    strain limit, every contact (separation, Coulomb friction), pins — together
//   impacts    the fail-safe with the last word: collider paths, swept tests, impact zones
//   health     finite state and sane speeds; a failed frame is retried with smaller substeps
//
// Around the substeps, per frame: the StagePlanner decides which cloths sleep through it and
// whether pairs need detecting; a cloth whose pins all jump is carried with them (teleport); the
// HealthMonitor's checks decide a retry with twice the substeps or a rollback. All cloths of a
// frame take the same substeps, so contact between cloths is resolved in every substep like
// contact within one.
#pragma once

#include "HealthMonitor.h"
#include "StagePlanner.h"
#include "contact/ContactDetector.h"
#include "contact/ContactProjector.h"
#include "contact/ContactSet.h"
#include "contact/ContactSpace.h"
#include "contact/ImpactResolver.h"
#include "contact/SelfContactPenalty.h"
#include "integrators/Integrator.h"

#include <weft/engine/StepStats.h>
#include <weft/threading/TaskSystem.h>

#include <span>
#include <vector>

namespace weft {

class Cloth;

/// A collider as the world holds it at the start of a frame.
struct ColliderSource {
  const Shape* shape = nullptr;  ///< posed at the frame start
  Real friction = 0.3;           ///< ColliderSettings::friction
};

class SubstepPipeline {
 public:
  /// `skipStages`: WorldSettings::skipUnneededStages.
  SubstepPipeline(TaskSystem* tasks, bool skipStages);

  /// Steps `cloths` (the world's, in slot order) by frameDt from world time t against
  /// `colliders`, whose motions are constant over the frame. Adds what it did to `stats`.
  void stepFrame(std::span<Cloth* const> cloths, std::span<const ColliderSource> colliders, Real t,
                 Real frameDt, const StepPlan& plan, StepStats& stats);

  /// The world created or destroyed a cloth: the next frame rebuilds the contact space. (A new
  /// cloth may live at a destroyed one's address, so comparing pointers cannot tell.)
  void clothsChanged() { m_clothsChanged = true; }

 private:
  // The substeps of one attempt at the frame; the health check that failed, or None.
  HealthFailure runSubsteps(Real t, Real frameDt, Index substeps, StepStats& stats);
  // The most substeps a frame past its strain limit is redone with: the smallest
  // strainRetrySubsteps of the stepping cloths, 0 when any has fixed substeps or the plan fixes
  // them (a budget's plan must replay as planned).
  Index strainRetryLimit(std::span<Cloth* const> cloths, const StepPlan& plan) const;
  // Whether redoing the frame with twice the substeps may help: a stepping cloth ends past its
  // strain limit + kStrainLimitSlack, unless it started past it too and the retries of the frames
  // before left it there (pins or a tangle hold it: more substeps change nothing).
  bool strainRetryHelps(std::span<Cloth* const> cloths) const;
  // One substep (see the file comment).
  HealthFailure substep(Real t, Real h, Index index, StepStats& stats);
  void pose(Index index, Real h);
  void solve(Real t, Real h, StepStats& stats);
  void rebuild(std::span<Cloth* const> cloths);

  TaskSystem* m_tasks;
  bool m_skipStages;
  bool m_clothsChanged = true;
  ContactSpace m_space;
  StagePlanner m_planner;
  ContactDetector m_detector;
  ContactProjector m_projector;
  ImpactResolver m_impacts;
  ContactSet m_contacts;
  std::vector<SolveConstraint> m_constraints;
  std::vector<FaceSupport> m_supports;
  std::vector<FaceSupport> m_frameStartSupports;  // restored with the cloths for a retry
  std::vector<ColliderFrame> m_colliders;        // this substep's
  std::vector<ColliderFrame> m_frameColliders;   // at the frame start (sleep decisions)
  std::vector<RigidMotion> m_frameStartMotions;
  std::vector<char> m_stepping;                  // per cloth: steps this frame
  std::vector<char> m_yanked;                    // per cloth: its pins make every substep hard
  std::vector<Real> m_solveImpulses;             // per vertex, m/s
  Vec3Array m_solvedPositions;                   // x after the solve (the detection's end)
  std::vector<Index> m_constrainedCollider;      // per vertex, kInvalidIndex: none
  std::vector<Real> m_startStrain, m_startKinetic;  // per cloth, at the frame start
  std::vector<Real> m_endStrain;  // per stepping cloth, at the end of the last healthy attempt
  // Per cloth: it ended its last stepped frames past its strain limit, retries failing to help.
  std::vector<char> m_strainRetriesFailed;
  std::vector<IntegratorReport> m_reports;       // per cloth, this attempt
  std::vector<Index> m_pairContacts;             // per cloth, this substep
  std::vector<std::vector<SelfContactFeatures>> m_selfContacts;  // per cloth, this substep
  Real m_contactMargin = 0;
  ProjectionSettings m_projection;
};

}  // namespace weft
