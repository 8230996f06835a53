#include "SubstepPipeline.h"

#include "Cloth.h"

#include <weft/engine/Material.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace weft {
namespace {

// How far (in contact thicknesses) the triangles under a broad-phase leaf may move before the
// leaf's box is refit: far above the creep of cloth at rest, far below anything that loosens
// the boxes measurably. The pairs found never change.
constexpr Real kRefitMotionPerThickness = 0.02;
// A vertex within its thickness plus this fraction of the mean edge length of a collider after
// the solve is a contact of the projection: one iteration moves a vertex far less than that, and
// the impact stage still catches what is farther.
constexpr Real kColliderMarginPerEdge = 0.5;
// Rounds of projection and impacts after the first, while the impact pass leaves an edge over
// its limit.
constexpr int kStrainRounds = 2;

// Whether `strain` is past the cloth's strain limit + kStrainLimitSlack (no limit: never).
bool pastLimit(const Cloth& cloth, Real strain) {
  const Real limit = cloth.settings().material.strainLimit;
  return limit > 0 && std::isfinite(limit) && strain > limit + kStrainLimitSlack;
}

// The strain `cloth` ends the frame with, into the stats; a cloth past its limit is reported,
// never passed off as ok (StepStatus::StrainLimitExceeded).
void reportStrain(const Cloth& cloth, Real strain, StepStats& stats) {
  stats.maxStrain = std::max(stats.maxStrain, strain);
  if (pastLimit(cloth, strain)) {
    ++stats.clothsOverStrainLimit;
    stats.status |= StepStatus::StrainLimitExceeded;
  }
}

// Adds the counters the substeps of an attempt collect to the frame's statistics.
void addSubstepCounters(const StepStats& from, StepStats& to) {
  to.assemblyMs += from.assemblyMs;
  to.solveMs += from.solveMs;
  to.linearSolves += from.linearSolves;
  to.cgIterations += from.cgIterations;
  to.cgResidual = std::max(to.cgResidual, from.cgResidual);
  to.contacts += from.contacts;
  to.faceContacts += from.faceContacts;
  to.selfContacts += from.selfContacts;
  to.selfImpacts += from.selfImpacts;
  to.impactZones += from.impactZones;
  to.frozenVertices += from.frozenVertices;
  to.unresolvedContacts += from.unresolvedContacts;
  to.strainLimitIterations += from.strainLimitIterations;
  to.strainLimitEdgesOver += from.strainLimitEdgesOver;
  to.colliderNarrowPhases += from.colliderNarrowPhases;
  to.colliderNarrowPhasesSkipped += from.colliderNarrowPhasesSkipped;
  to.selfCollisionPasses += from.selfCollisionPasses;
  to.selfCollisionSkipped += from.selfCollisionSkipped;
  to.bendingAssemblies += from.bendingAssemblies;
  to.dampingJacobians += from.dampingJacobians;
  to.clothContacts += from.clothContacts;
  to.bvhNodesRefit += from.bvhNodesRefit;
  to.bvhNodesSkipped += from.bvhNodesSkipped;
  to.squeezedVertices += from.squeezedVertices;
}

}  // namespace

SubstepPipeline::SubstepPipeline(TaskSystem* tasks, bool skipStages)
    : m_tasks(tasks), m_skipStages(skipStages), m_planner(skipStages) {}

void SubstepPipeline::rebuild(std::span<Cloth* const> cloths) {
  m_space.build(cloths);
  m_planner.build(m_space);
  m_detector.build(m_space, m_tasks);
  m_impacts.build(m_space, m_tasks);
  Real thickness = 0;
  m_contactMargin = 0;
  for (Cloth* cloth : cloths) {
    thickness = std::max(thickness, cloth->settings().material.thickness);
    m_contactMargin = std::max({m_contactMargin, cloth->settings().material.thickness,
                                kColliderMarginPerEdge * cloth->meanEdgeLength()});
  }
  const Real refit = m_skipStages ? kRefitMotionPerThickness * thickness : -1;
  m_detector.setRefitMargin(refit);
  m_impacts.setRefitMargin(refit);
  m_detector.setSkipping(m_skipStages);
  m_impacts.setSkipping(m_skipStages);
  const Index n = m_space.vertexCount();
  m_solveImpulses.assign(n, 0);
  m_constrainedCollider.assign(n, kInvalidIndex);
  m_stepping.assign(cloths.size(), 0);
  m_yanked.assign(cloths.size(), 0);
  m_startStrain.assign(cloths.size(), 0);
  m_startKinetic.assign(cloths.size(), 0);
  m_endStrain.assign(cloths.size(), 0);
  m_strainRetriesFailed.assign(cloths.size(), 0);
  m_reports.assign(cloths.size(), IntegratorReport{});
  m_pairContacts.assign(cloths.size(), 0);
  m_selfContacts.resize(cloths.size());
  m_supports.clear();
}

void SubstepPipeline::stepFrame(std::span<Cloth* const> cloths,
                                std::span<const ColliderSource> colliders, Real t, Real frameDt,
                                const StepPlan& plan, StepStats& stats) {
  if (cloths.empty()) return;
  if (m_clothsChanged || !m_space.builtFor(cloths)) {
    rebuild(cloths);
    m_clothsChanged = false;
  }
  // The colliders at the frame start, and their motions for the substeps.
  m_frameColliders.resize(colliders.size());
  m_colliders.resize(colliders.size());
  m_frameStartMotions.clear();
  for (std::size_t k = 0; k < colliders.size(); ++k) {
    ColliderFrame& frame = m_frameColliders[k];
    frame.shape = *colliders[k].shape;
    frame.start = frame.end = motion(*colliders[k].shape);
    frame.friction = colliders[k].friction;
    m_frameStartMotions.push_back(frame.start);
  }

  // Which cloths step; the others are obstacles this frame.
  bool anyStepping = false;
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    Cloth& cloth = *cloths[c];
    bool woke = false;
    m_stepping[c] = m_planner.steps(cloth, m_frameColliders, frameDt, woke);
    stats.wokenCloths += woke;
    stats.sleepingCloths += !m_stepping[c];
    m_space.setMovable(c, m_stepping[c]);
    anyStepping = anyStepping || m_stepping[c];
  }
  if (!anyStepping) {
    for (Cloth* cloth : cloths) {
      reportStrain(*cloth, cloth->maxStrain(), stats);
      stats.potentialEnergy += cloth->lastPotential();
    }
    return;
  }

  // Teleports, the solver's limits, the substeps every stepping cloth needs (the most of them).
  bool unstable = false;
  Index substeps = 0;
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    if (!m_stepping[c]) continue;
    Cloth& cloth = *cloths[c];
    stats.teleportedCloths += cloth.beginFrame(t, frameDt, plan);
    bool predictedUnstable = false;
    substeps = std::max(substeps, cloth.plannedSubsteps(frameDt, &predictedUnstable, std::nullopt));
    unstable = unstable || predictedUnstable;
    m_startStrain[c] = cloth.maxStrain();
    m_startKinetic[c] = cloth.kineticEnergy();
  }
  if (plan.substeps > 0) {
    substeps = plan.substeps;
    unstable = false;
    for (std::size_t c = 0; c < cloths.size(); ++c) {
      const Cloth& cloth = *cloths[c];
      unstable = unstable || (m_stepping[c] &&
                              cloth.settings().solver.integrator != IntegratorKind::ImplicitEuler &&
                              frameDt / substeps > cloth.stableStep());
    }
  }
  if (unstable) stats.status |= StepStatus::Unstable;

  // Attempts: a frame that fails a health check is restored and retried with twice the
  // substeps; after kMaxHealthRetries it is rolled back. A healthy frame that leaves a cloth past
  // its strain limit is redone with twice the substeps too, within strainRetrySubsteps, when the
  // substeps are automatic and the retry can help (strainRetryHelps): the contacts of a squeeze
  // move cloth several thicknesses a substep at 60 Hz, more than one projection can untangle.
  const Index strainRetryCap = strainRetryLimit(cloths, plan);
  // A retry starts where the frame started: the cloths, and the face supports the last frame
  // left for this one's first solve.
  m_frameStartSupports = m_supports;
  auto restoreFrameStart = [&] {
    for (std::size_t c = 0; c < cloths.size(); ++c) {
      if (m_stepping[c]) cloths[c]->restoreFrameStart();
    }
    m_supports = m_frameStartSupports;
  };
  for (int attempt = 0;; ++attempt) {
    StepStats attemptStats;
    HealthFailure failure = runSubsteps(t, frameDt, substeps, attemptStats);
    if (failure == HealthFailure::None) {
      WEFT_PROFILE_ZONE("health");
      for (std::size_t c = 0; c < cloths.size() && failure == HealthFailure::None; ++c) {
        if (!m_stepping[c]) continue;
        const Cloth& cloth = *cloths[c];
        m_endStrain[c] = cloth.maxStrain();
        failure = checkFrameHealth(cloth, m_startStrain[c], m_startKinetic[c], m_endStrain[c],
                                   cloth.kineticEnergy(), m_frameStartMotions);
      }
    }
    if (failure == HealthFailure::None && substeps * 2 <= strainRetryCap &&
        strainRetryHelps(cloths)) {
      restoreFrameStart();
      ++stats.strainRetries;
      substeps *= 2;
      --attempt;  // not a health retry: the doubling itself bounds these
      continue;
    }
    if (failure == HealthFailure::None) {
      addSubstepCounters(attemptStats, stats);  // the successful attempt's are the frame's
      stats.substeps = substeps;
      break;
    }
    if (stats.healthFailure == HealthFailure::None) stats.healthFailure = failure;
    restoreFrameStart();
    stats.status |= StepStatus::Unstable;
    if (attempt == kMaxHealthRetries) {
      stats.status |= StepStatus::RolledBack;
      stats.substeps = substeps;
      break;
    }
    stats.status |= StepStatus::RetriedWithSmallerStep;
    substeps *= 2;
  }
  if (stats.squeezedVertices > 0) stats.status |= StepStatus::Squeezed;
  if (stats.frozenVertices > 0) stats.status |= StepStatus::ContactsFrozen;
  if (stats.unresolvedContacts > 0) stats.status |= StepStatus::ContactsUnresolved;
  const bool rolledBack = hasFlag(stats.status, StepStatus::RolledBack);

  // The frame's end: pins, sleep, the figures of the report.
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    Cloth& cloth = *cloths[c];
    if (m_stepping[c]) {
      const bool pinsMoved = cloth.largestPinTravel() > 0;
      const IntegratorReport& report = m_reports[c];
      cloth.setLastPotential(rolledBack ? cloth.frameStartPotential() : report.potentialEnergy);
      if (!report.cgConverged) stats.status |= StepStatus::SolverNotConverged;
      cloth.endFrame();
      if (!hasFlag(stats.status, StepStatus::Unstable)) {
        m_planner.afterFrame(cloth, m_frameColliders, frameDt, pinsMoved);
      } else {
        cloth.sleepState().quietFrames = 0;
      }
    }
    stats.solvedUnknowns += m_stepping[c] ? m_reports[c].solvedUnknowns : 0;
    const ClothStageCounts counts = cloth.takeStageCounts();
    stats.bendingAssemblies += counts.bendingAssemblies;
    stats.dampingJacobians += counts.dampingJacobians;
    // A rolled-back cloth is back at its frame start, whose strain was measured then.
    const Real strain = !m_stepping[c] ? cloth.maxStrain()
                        : rolledBack   ? m_startStrain[c]
                                       : m_endStrain[c];
    reportStrain(cloth, strain, stats);
    if (m_stepping[c]) {
      m_strainRetriesFailed[c] =
          pastLimit(cloth, strain) && (stats.strainRetries > 0 || m_strainRetriesFailed[c]);
    }
    stats.kineticEnergy += cloth.kineticEnergy();
    stats.maxSpeed = std::max(stats.maxSpeed, cloth.maxSpeed());
    stats.potentialEnergy += cloth.lastPotential();
  }
}

Index SubstepPipeline::strainRetryLimit(std::span<Cloth* const> cloths, const StepPlan& plan) const {
  if (plan.substeps > 0) return 0;
  Index cap = std::numeric_limits<Index>::max();
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    if (!m_stepping[c]) continue;
    const SolverSettings& solver = cloths[c]->settings().solver;
    if (solver.substeps > 0) return 0;
    cap = std::min({cap, solver.strainRetrySubsteps, solver.maxSubsteps});
  }
  return cap == std::numeric_limits<Index>::max() ? 0 : cap;
}

bool SubstepPipeline::strainRetryHelps(std::span<Cloth* const> cloths) const {
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    if (!m_stepping[c] || !pastLimit(*cloths[c], m_endStrain[c])) continue;
    if (!(m_strainRetriesFailed[c] && pastLimit(*cloths[c], m_startStrain[c]))) return true;
  }
  return false;
}

HealthFailure SubstepPipeline::runSubsteps(Real t, Real frameDt, Index substeps,
                                           StepStats& stats) {
  const Real h = frameDt / substeps;
  const std::span<Cloth* const> cloths = m_space.cloths();
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    m_reports[c] = IntegratorReport{};
    if (!m_stepping[c]) continue;
    // Pins yanked far make every substep hard (tightPinTravel): pins move on straight lines
    // through the frame, so each substep has 1/substeps of the travel.
    const Cloth& cloth = *cloths[c];
    m_yanked[c] = cloth.largestPinTravel() >=
                  cloth.settings().solver.tightPinTravel * cloth.meanEdgeLength() * Real(substeps);
  }
  for (Index index = 0; index < substeps; ++index) {
    const HealthFailure failure = substep(t + index * h, h, index, stats);
    if (failure != HealthFailure::None) return failure;
  }
  return HealthFailure::None;
}

void SubstepPipeline::pose(Index index, Real h) {
  for (std::size_t k = 0; k < m_colliders.size(); ++k) {
    ColliderFrame& collider = m_colliders[k];
    collider.shape = m_frameColliders[k].shape;
    collider.start = advanceMotion(m_frameStartMotions[k], index * h);
    collider.end = advanceMotion(m_frameStartMotions[k], (index + 1) * h);
    collider.friction = m_frameColliders[k].friction;
    (void)setMotion(collider.shape, collider.end);
  }
}

void SubstepPipeline::solve(Real t, Real h, StepStats& stats) {
  const std::span<Cloth* const> cloths = m_space.cloths();
  std::fill(m_solveImpulses.begin(), m_solveImpulses.end(), Real(0));
  std::fill(m_constrainedCollider.begin(), m_constrainedCollider.end(), kInvalidIndex);
  for (const SolveConstraint& constraint : m_constraints) {
    m_constrainedCollider[constraint.vertex] = constraint.collider;
  }
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    if (!m_stepping[c]) continue;
    Cloth& cloth = *cloths[c];
    const Index first = m_space.firstVertex(c);
    // This cloth's constraints: they are sorted by vertex of the space.
    const auto begin = std::lower_bound(
        m_constraints.begin(), m_constraints.end(), first,
        [](const SolveConstraint& constraint, Index vertex) { return constraint.vertex < vertex; });
    const auto end = std::lower_bound(
        begin, m_constraints.end(), first + cloth.vertexCount(),
        [](const SolveConstraint& constraint, Index vertex) { return constraint.vertex < vertex; });
    IntegratorReport report;
    const std::span<const SolveConstraint> own(m_constraints.data() + (begin - m_constraints.begin()),
                                               std::size_t(end - begin));
    cloth.integrate(t, h, own, first, m_yanked[c] || cloth.jammed(), report);
    const bool firstSubstep = m_reports[c].linearSolves == 0 && m_reports[c].cgIterations == 0 &&
                              m_reports[c].assemblyMs == 0;
    if (firstSubstep) cloth.setFrameStartPotential(report.potentialEnergy);
    IntegratorReport& total = m_reports[c];
    total.linearSolves += report.linearSolves;
    total.cgIterations += report.cgIterations;
    total.cgResidual = report.cgResidual;
    total.cgConverged = total.cgConverged && report.cgConverged;
    total.potentialEnergy = report.potentialEnergy;
    total.assemblyMs += report.assemblyMs;
    total.solveMs += report.solveMs;
    total.solvedUnknowns = report.solvedUnknowns;
    stats.linearSolves += report.linearSolves;
    stats.cgIterations += report.cgIterations;
    stats.cgResidual = std::max(stats.cgResidual, report.cgResidual);
    stats.assemblyMs += report.assemblyMs;
    stats.solveMs += report.solveMs;
    const std::span<const Real> impulses = cloth.solveContactImpulses();
    std::copy(impulses.begin(), impulses.end(), m_solveImpulses.begin() + first);
  }
}

HealthFailure SubstepPipeline::substep(Real t, Real h, Index index, StepStats& stats) {
  DetectionCounts counts;
  pose(index, h);
  m_space.gather();
  m_space.markStart();
  m_detector.constrain(m_space, m_colliders, h, m_supports, m_constraints, counts);
  solve(t, h, stats);
  m_space.gather();
  Index selfNeeded = 0, selfSkipped = 0;
  const bool pairs = m_planner.pairsNeeded(m_space, m_stepping, selfNeeded, selfSkipped);
  m_detector.detect(m_space, m_colliders, m_solveImpulses, m_constrainedCollider, pairs,
                    m_contactMargin, m_contacts, counts);
  // The pairs the solve held: their penalty's impulse is their friction bound.
  const std::span<Cloth* const> solved = m_space.cloths();
  for (std::size_t k = m_contacts.firstPair; k < m_contacts.size(); ++k) {
    Contact& contact = m_contacts.contacts[k];
    const Index c = m_space.owner[contact.vertices[0]];
    if (m_space.owner[contact.vertices[3]] != c || !m_stepping[c]) continue;
    std::array<Index, 4> local = contact.vertices;
    for (Index& vertex : local) vertex -= m_space.firstVertex(c);
    contact.solveImpulse = solved[c]->selfContactImpulse(contact.kind, local);
  }
  m_solvedPositions = m_space.x;
  ProjectionReport projected =
      m_projector.project(m_space, m_contacts, m_colliders, h, m_projection, m_supports);
  const DetectedPairs detectedPairs{&m_detector.featurePairs(), m_solvedPositions,
                                    m_detector.pairMargin()};
  ImpactReport impacts =
      m_impacts.resolve(m_space, m_contacts, m_colliders, h, pairs, detectedPairs);
  // The impact pass has the last word and may stretch edges the projection had limited (a
  // vertex held at its start while its neighbours moved): project and resolve again, a few
  // rounds at most, while an edge stays over its limit.
  for (int round = 0; round < kStrainRounds && impacts.impacts + impacts.frozenVertices > 0 &&
                      m_space.edgesOverLimit(m_projection.strainTolerance) > 0;
       ++round) {
    const ProjectionReport again =
        m_projector.project(m_space, m_contacts, m_colliders, h, m_projection, m_supports);
    projected.iterations += again.iterations;
    projected.edgesOverLimit = again.edgesOverLimit;
    projected.contactsViolated = again.contactsViolated;
    const ImpactReport more =
        m_impacts.resolve(m_space, m_contacts, m_colliders, h, pairs, detectedPairs);
    impacts.impacts += more.impacts;
    impacts.impactZones += more.impactZones;
    impacts.frozenVertices = more.frozenVertices;
    impacts.colliderCorrections += more.colliderCorrections;
  }
  m_space.scatter();

  // What the substep did.
  std::fill(m_pairContacts.begin(), m_pairContacts.end(), 0);
  Index faceContacts = 0;
  for (std::size_t k = 0; k < m_contacts.size(); ++k) {
    const Contact& contact = m_contacts.contacts[k];
    if (contact.kind == ContactKind::FaceCollider) ++faceContacts;
    if (k < m_contacts.firstPair) continue;
    const Index a = m_space.owner[contact.vertices[0]], b = m_space.owner[contact.vertices[3]];
    ++m_pairContacts[a];
    if (b != a) {
      ++m_pairContacts[b];
      ++stats.clothContacts;
    } else {
      ++stats.selfContacts;
    }
  }
  const std::span<Cloth* const> cloths = m_space.cloths();
  // Each cloth's pairs within itself, which its next solve holds (SelfContactPenalty.h).
  for (std::vector<SelfContactFeatures>& features : m_selfContacts) features.clear();
  for (std::size_t k = m_contacts.firstPair; k < m_contacts.size(); ++k) {
    const Contact& contact = m_contacts.contacts[k];
    const Index c = m_space.owner[contact.vertices[0]];
    if (m_space.owner[contact.vertices[3]] != c) continue;
    const Index first = m_space.firstVertex(c);
    SelfContactFeatures features{contact.kind, contact.vertices, contact.normal};
    for (Index& vertex : features.vertices) vertex -= first;
    m_selfContacts[c].push_back(features);
  }
  for (std::size_t c = 0; c < cloths.size(); ++c) {
    if (!m_stepping[c]) continue;
    cloths[c]->setSelfContacts(m_selfContacts[c]);
    // Contact-aware accuracy: a substep dense in cloth contacts makes the next one hard.
    Cloth& cloth = *cloths[c];
    cloth.setJammed(Real(m_pairContacts[c]) >=
                    cloth.settings().solver.tightSelfContactDensity * Real(cloth.vertexCount()));
  }
  stats.colliderNarrowPhases += counts.colliderPairsTested;
  stats.colliderNarrowPhasesSkipped += counts.colliderPairsSkipped;
  stats.squeezedVertices += counts.squeezedVertices;
  stats.selfCollisionPasses += selfNeeded;
  stats.selfCollisionSkipped += selfSkipped;
  stats.contacts = projected.colliderContacts;
  stats.faceContacts += faceContacts;
  stats.selfImpacts += impacts.impacts;
  stats.impactZones += impacts.impactZones;
  stats.frozenVertices += impacts.frozenVertices;
  stats.unresolvedContacts += projected.contactsViolated;
  stats.strainLimitIterations += projected.iterations;
  stats.strainLimitEdgesOver += projected.edgesOverLimit;
  const Bvh::RefitCounts detected = m_detector.takeRefitCounts();
  const Bvh::RefitCounts swept = m_impacts.takeRefitCounts();
  stats.bvhNodesRefit += detected.refitNodes + swept.refitNodes;
  stats.bvhNodesSkipped += detected.skippedNodes + swept.skippedNodes;
  WEFT_PROFILE_ZONE("health");
  return checkSubstepHealth(m_space);
}

}  // namespace weft
