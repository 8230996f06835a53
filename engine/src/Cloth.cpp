#include "Cloth.h"

#include "ClothSettingsValidation.h"
#include "HealthMonitor.h"
#include "solver/MulticolorOrdering.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>

namespace weft {
namespace {

// Tolerated growth of the fastest mode per explicit step: a factor e over 10⁶ steps. Small enough
// that an explicit method that passes it does not blow up within any run we make.
constexpr Real kExplicitGrowthPerStep = 1e-6;
// Safety factor on the stable-step estimate (it is an upper bound of ω, but at the rest state).
constexpr Real kStableStepSafety = 0.9;

}  // namespace

Result<std::unique_ptr<Cloth>> Cloth::create(std::shared_ptr<const ClothModel> model,
                                             const ClothSettings& settings,
                                             const WorldSettings& world, TaskSystem* tasks) {
  if (std::string problem = validateClothSettings(model.get(), settings); !problem.empty()) {
    return Error{problem};
  }
  std::vector<Real> masses = settings.vertexMasses.empty()
                                ? model->vertexMasses(settings.material.arealDensity)
                                : settings.vertexMasses;
  return std::unique_ptr<Cloth>(
      new Cloth(std::move(model), settings, world, std::move(masses), tasks));
}

Cloth::Cloth(std::shared_ptr<const ClothModel> model, const ClothSettings& settings,
             const WorldSettings& world, std::vector<Real> masses, TaskSystem* tasks)
    : m_model(std::move(model)),
      m_tasks(tasks),
      m_settings(settings),
      m_forces(*m_model,
               ClothForceSettings{settings.forceModel, settings.material, settings.springs,
                                  world.gravity, world.wind, StiffnessMode::Definite,
                                  world.skipUnneededStages},
               std::move(masses), tasks) {
  m_integrator = Integrator::create(settings.solver.integrator, settings.solver);
  const Index n = m_model->vertexCount();
  m_positions.resize(n);
  for (Index i = 0; i < n; ++i) {
    m_positions[i] = settings.rotation * m_model->restPositions()[i] + settings.translation;
  }
  m_velocities.assign(n, Vec3::Zero());
  m_frameStartPositions = m_positions;
  m_frameStartVelocities = m_velocities;
  m_solveContactImpulses.assign(n, 0);
  // The integrator's carried state, copied at every frame start.
  m_frameStartCarried.reserve(m_integrator->carriedStateCapacity(std::size_t(n)));

  // Pins start where their vertices are.
  const std::vector<Index>& pins = settings.pinnedVertices;
  std::vector<Index> order(pins.size());
  std::iota(order.begin(), order.end(), Index(0));
  std::sort(order.begin(), order.end(), [&](Index a, Index b) { return pins[a] < pins[b]; });
  for (Index k : order) {
    m_pinnedSorted.push_back(pins[k]);
    m_pinSlotOfSorted.push_back(k);
  }
  m_pinnedMask.assign(n, 0);
  for (Index p : pins) m_pinnedMask[p] = 1;
  {
    std::vector<Index> slotOf(n, kInvalidIndex);
    for (std::size_t k = 0; k < pins.size(); ++k) slotOf[pins[k]] = Index(k);
    for (const Edge& edge : m_model->edges()) {
      const Index a = slotOf[edge.vertices[0]], b = slotOf[edge.vertices[1]];
      if (a != kInvalidIndex && b != kInvalidIndex) m_pinnedEdges.push_back({a, b, edge.restLength});
    }
  }
  buildSystemRows();
  m_pinStart.resize(pins.size());
  for (std::size_t k = 0; k < pins.size(); ++k) m_pinStart[k] = m_positions[pins[k]];
  m_pinEnd = m_pinStart;
  for (const Edge& edge : m_model->edges()) m_meanEdgeLength += edge.restLength;
  if (!m_model->edges().empty()) m_meanEdgeLength /= Real(m_model->edges().size());
  m_inverseMasses.resize(n);
  const std::vector<Real>& mass = m_forces.masses();
  for (Index i = 0; i < n; ++i) m_inverseMasses[i] = m_pinnedMask[i] ? 0 : 1 / mass[i];
  // Self-contacts in an implicit solve, when asked: k = selfContactStiffness × the stretch
  // stiffness, N/m (SelfContactPenalty.h).
  if (settings.solver.integrator == IntegratorKind::ImplicitEuler ||
      settings.solver.integrator == IntegratorKind::Bdf2) {
    const Real stretch = settings.forceModel == ForceModel::MassSpring
                             ? settings.springs.structuralStiffness
                             : std::max(settings.material.warpStretchStiffness,
                                        settings.material.weftStretchStiffness);
    m_selfContactStiffness = settings.solver.selfContactStiffness * stretch;
  }
  estimateStiffestMode();
}

void Cloth::buildSystemRows() {
  // Pinned vertices leave the implicit system when asked (and when the integrator has one);
  // explicit integrators only read forces, which cover every vertex either way.
  const Index n = m_model->vertexCount();
  const bool remove = m_settings.solver.removePinnedVertices &&
                      m_settings.solver.integrator == IntegratorKind::ImplicitEuler;
  m_freeVertexMap.build(n, remove ? std::span<const Index>(m_pinnedSorted) : std::span<const Index>());
  m_forces.buildSystem(m_freeVertexMap, m_matrix, m_pinnedCoupling);
  if (m_vertexColors.size() != n) {
    m_vertexColors = MulticolorOrdering::colorVertices(n, m_forces.potentialCoupledPairs());
  }
  m_rowColors.resize(m_freeVertexMap.rowCount());
  for (Index row = 0; row < m_freeVertexMap.rowCount(); ++row) {
    m_rowColors[row] = m_vertexColors[m_freeVertexMap.vertex(row)];
  }
  m_contactRows.clear();
  m_contactRows.reserve(m_freeVertexMap.rowCount());
}

void Cloth::estimateStiffestMode() {
  // A(h) = M − h D − h² K with D = ∂f/∂v, K = ∂f/∂x, so from h = ±1:
  //   K = M − (A(1) + A(−1)) / 2,   D = (A(−1) − A(1)) / 2.
  // Gershgorin on M^{-1/2}(−K)M^{-1/2} bounds ω², and on M^{-1/2}(−D)M^{-1/2} the damping rate.
  const Index n = vertexCount();
  Vec3Array f, product, zero(n, Vec3::Zero());
  BlockSparseMatrix plus = m_matrix, minus = m_matrix;
  PinnedCoupling coupling = m_pinnedCoupling;  // written by the assembly, not read here
  m_forces.assemble(m_positions, zero, 1.0, plus, f, zero, product, &coupling);
  m_forces.assemble(m_positions, zero, -1.0, minus, f, zero, product, &coupling);
  std::vector<bool> pinned(n, false);
  for (Index p : m_pinnedSorted) pinned[p] = true;
  const std::vector<Real>& mass = masses();
  Real omegaSquared = 0, dampingRate = 0;
  // Rows and columns of the system are vertices of m_freeVertexMap (pins may have none).
  for (Index systemRow = 0; systemRow < plus.blockRows(); ++systemRow) {
    const Index row = m_freeVertexMap.vertex(systemRow);
    if (pinned[row]) continue;
    Real stiffnessSum = 0, dampingSum = 0;
    for (Index slot = plus.rowBegin(systemRow); slot < plus.rowEnd(systemRow); ++slot) {
      const Index column = m_freeVertexMap.vertex(plus.column(slot));
      if (pinned[column]) continue;
      const Mat3 massBlock = column == row ? Mat3(mass[row] * Mat3::Identity()) : Mat3::Zero();
      const Mat3 stiffness = massBlock - 0.5 * (plus.block(slot) + minus.block(slot));
      const Mat3 damping = 0.5 * (minus.block(slot) - plus.block(slot));
      const Real scale = 1.0 / std::sqrt(mass[row] * mass[column]);
      stiffnessSum += scale * stiffness.cwiseAbs().rowwise().sum().maxCoeff();
      dampingSum += scale * damping.cwiseAbs().rowwise().sum().maxCoeff();
    }
    omegaSquared = std::max(omegaSquared, stiffnessSum);
    dampingRate = std::max(dampingRate, dampingSum);
  }
  m_stiffestFrequency = std::sqrt(omegaSquared);
  m_stiffestDampingRate = dampingRate;
  m_stableStep = stableStepLimit(m_settings.solver.integrator, m_stiffestFrequency,
                                 m_stiffestDampingRate, kExplicitGrowthPerStep);
}

Index Cloth::plannedSubsteps(Real frameDt, bool* predictedUnstable,
                             const std::optional<RigidFit>& carry) const {
  const SolverSettings& solver = m_settings.solver;
  if (predictedUnstable) *predictedUnstable = false;
  const bool implicit = solver.integrator == IntegratorKind::ImplicitEuler;
  Index substeps = solver.substeps;
  if (substeps == 0) {
    const Real limit = implicit ? solver.maxImplicitStep : kStableStepSafety * m_stableStep;
    // 1e-9 forgives round-off: 1/60 s at a 1/60 s limit is one substep, not two.
    const Real wanted = limit > 0 ? std::ceil(frameDt / limit * (1 - 1e-9)) : Real(solver.maxSubsteps + 1);
    substeps = static_cast<Index>(std::clamp<Real>(wanted, 1, Real(solver.maxSubsteps) + 1));
    if (substeps > solver.maxSubsteps) {
      substeps = solver.maxSubsteps;
      if (predictedUnstable) *predictedUnstable = true;
    }
    // Pins are kinematic drivers: no substep may carry one farther than
    // maxPinTravelPerSubstep edges (SolverSettings says why). Only a fast pin asks for more; the
    // cap still holds. In a teleport frame the cloth is carried and the pins travel relative
    // to it.
    Real travel = 0;
    for (std::size_t k = 0; k < m_pinEnd.size(); ++k) {
      const Vec3 start = carry ? carry->apply(m_pinStart[k]) : m_pinStart[k];
      travel = std::max(travel, (m_pinEnd[k] - start).norm());
    }
    const Real reach = solver.maxPinTravelPerSubstep * m_meanEdgeLength;
    const Real pinWanted = reach > 0 ? std::ceil(travel / reach * (1 - 1e-9)) : 0;
    if (pinWanted > Real(substeps)) {
      substeps = static_cast<Index>(std::min<Real>(pinWanted, Real(solver.maxSubsteps)));
    }
  } else if (!implicit && frameDt / substeps > m_stableStep && predictedUnstable) {
    *predictedUnstable = true;
  }
  return substeps;
}

Real Cloth::largestPinTravel() const {
  Real travel = 0;
  for (std::size_t k = 0; k < m_pinEnd.size(); ++k) {
    travel = std::max(travel, (m_pinEnd[k] - m_pinStart[k]).norm());
  }
  return travel;
}

std::optional<RigidFit> Cloth::teleportMotion() const {
  const SolverSettings& solver = m_settings.solver;
  if (m_pinEnd.empty()) return std::nullopt;
  const Vec3& up = m_forces.settings().gravity;
  // Every pin must jump: one pin yanked far while the others stay is motion to simulate (the
  // substep rule follows it), not the whole cloth changing place.
  const Real threshold = solver.pinTeleportDistance * m_model->characteristicLength();
  bool everyPinJumped = threshold > 0;
  Real farthest = 0;
  for (std::size_t k = 0; k < m_pinEnd.size(); ++k) {
    const Real travel = (m_pinEnd[k] - m_pinStart[k]).norm();
    everyPinJumped = everyPinJumped && travel > threshold;
    farthest = std::max(farthest, travel);
  }
  if (everyPinJumped) return fitRigidMotion(m_pinStart, m_pinEnd, up);
  // A turn in place (SolverSettings::pinTeleportAngle): the pins near its axis hardly move, so
  // only the fit sees it. Pins that all stay within an edge are followed by one substep whatever
  // their turn, so the fit (a 3 × 3 SVD) runs only when some pin moved farther; a cloth whose pins
  // stand still or creep pays nothing.
  if (!(solver.pinTeleportAngle > 0) || !(farthest > m_meanEdgeLength)) return std::nullopt;
  const RigidFit fit = fitRigidMotion(m_pinStart, m_pinEnd, up);
  if (!(fit.angle() > solver.pinTeleportAngle)) return std::nullopt;
  // Rigid: every pin where the motion puts it, to within an edge (what one substep follows).
  // Otherwise the pins deform the cloth (a twist, one end swung round), which is to be simulated.
  for (std::size_t k = 0; k < m_pinEnd.size(); ++k) {
    if (!((fit.apply(m_pinStart[k]) - m_pinEnd[k]).norm() <= m_meanEdgeLength)) return std::nullopt;
  }
  return fit;
}

Real Cloth::computeForces(const Vec3Array& x, const Vec3Array& v, Real, Vec3Array& f) {
  m_stageCounts.bendingAssemblies += m_forces.evaluatesBending();
  return m_forces.computeForces(x, v, f);
}

Real Cloth::linearize(const Vec3Array& x, const Vec3Array& v, Real, Real h, Vec3Array& f,
                      const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity) {
  m_stageCounts.bendingAssemblies += m_forces.evaluatesBending();
  m_stageCounts.dampingJacobians += m_forces.formsDampingJacobians();
  const Real energy = m_forces.assemble(x, v, h, m_matrix, f, velocityForProduct,
                                        stiffnessTimesVelocity, &m_pinnedCoupling);
  addSelfContactTerms(x, h, velocityForProduct);
  return energy;
}

void Cloth::addSelfContactTerms(const Vec3Array& x, Real h, const Vec3Array& velocityForProduct) {
  // Every pair gives a term (ContactCoupling.h: h² k JᵀJ, the spring's normal force at x and
  // ∂f/∂x·v = −k J v), zero or pulling where it is apart: the integrator adds the forces to the
  // right-hand side itself and keeps a term only while it pushes at the end of the step. The
  // penalty's energy is no part of the reported potential: it is a device of the solve.
  m_contactCouplings.clear();  // keeps its capacity
  const Real k = m_selfContactStiffness;
  const Real thickness = m_settings.material.thickness;
  for (const SelfContactPair& pair : m_solvePairs) {
    const std::array<Vec3, 4> corners{x[pair.vertices[0]], x[pair.vertices[1]],
                                      x[pair.vertices[2]], x[pair.vertices[3]]};
    Vec3 relative = Vec3::Zero();
    for (int j = 0; j < 4; ++j) relative += pair.weights[j] * velocityForProduct[pair.vertices[j]];
    ContactCoupling term{pair.vertices, pair.weights, pair.normal, h * h * k, 0, 0};
    const Real restGap = penaltyRestGap(pair.gap, thickness);
    term.force = contactPenalty(corners, pair.weights, pair.normal, restGap, k).force;
    term.stiffnessTimesVelocity = -k * pair.normal.dot(relative);
    m_contactCouplings.push_back(term);
  }
}

void Cloth::applyPrescribedMotion(Real t, Vec3Array& x, Vec3Array& v) const {
  Real fraction = (t - m_frameStart) / m_frameLength;
  // Substep times are sums of h and miss the frame end by round-off: snap, so pins land on their
  // targets bit for bit at the end of every frame.
  if (std::abs(fraction - 1) < 1e-9) fraction = 1;
  for (std::size_t k = 0; k < m_pinnedSorted.size(); ++k) {
    const Index slot = m_pinSlotOfSorted[k];
    const Vec3& start = m_pinStart[slot];
    const Vec3& end = m_pinEnd[slot];
    // (1 − s)·start + s·end is exact at both ends, unlike start + s·(end − start).
    x[m_pinnedSorted[k]] = (1 - fraction) * start + fraction * end;
    v[m_pinnedSorted[k]] = (end - start) / m_frameLength;
  }
}

Status Cloth::setPinTargets(std::span<const Vec3> targets) {
  if (targets.size() != m_pinEnd.size()) {
    return Error{"setPinTargets: got " + std::to_string(targets.size()) + " targets for " +
                 std::to_string(m_pinEnd.size()) +
                 " pinned vertices; give one per entry of ClothSettings::pinnedVertices"};
  }
  for (std::size_t k = 0; k < targets.size(); ++k) {
    if (!targets[k].allFinite()) {
      return Error{"setPinTargets: target " + std::to_string(k) + " (vertex " +
                   std::to_string(m_settings.pinnedVertices[k]) + ") is NaN or infinite"};
    }
  }
  m_pinEnd.assign(targets.begin(), targets.end());
  return Status::success();
}

Status Cloth::checkPinnedEdges(std::span<const Vec3> targets) const {
  if (targets.size() != m_pinEnd.size()) return Status::success();  // setPinTargets names it
  for (const PinnedEdge& edge : m_pinnedEdges) {
    const Real length = (targets[edge.slots[1]] - targets[edge.slots[0]]).norm();
    // A non-finite target is setPinTargets' to name.
    if (!std::isfinite(length) || !(length > (1 + kDivergedStrain) * edge.restLength)) continue;
    char figures[128];
    std::snprintf(figures, sizeof figures, "%.3g m apart, %.3g times the %.3g m edge between them",
                  length, length / edge.restLength, edge.restLength);
    return Error{"setPinTargets: the targets of pinned vertices " +
                 std::to_string(m_settings.pinnedVertices[edge.slots[0]]) + " and " +
                 std::to_string(m_settings.pinnedVertices[edge.slots[1]]) + " are " + figures +
                 ", which no cloth survives (a frame that stretches an edge past " +
                 std::to_string(int(1 + kDivergedStrain)) +
                 " times its rest length is rolled back); move them together or unpin one"};
  }
  return Status::success();
}

Status Cloth::setExternalForces(std::span<const Vec3> forces) {
  if (!forces.empty() && forces.size() != m_positions.size()) {
    return Error{"setExternalForces: got " + std::to_string(forces.size()) +
                 " forces for a cloth of " + std::to_string(m_positions.size()) +
                 " vertices; give one per vertex, or none to remove them"};
  }
  for (std::size_t i = 0; i < forces.size(); ++i) {
    if (!forces[i].allFinite()) {
      return Error{"setExternalForces: the force on vertex " + std::to_string(i) +
                   " is NaN or infinite"};
    }
  }
  m_forces.setExternalForces(forces);
  m_sleep.wakeRequested = true;
  return Status::success();
}

Status Cloth::setState(std::span<const Vec3> positions, std::span<const Vec3> velocities) {
  const std::size_t n = m_positions.size();
  if (positions.size() != n || velocities.size() != n) {
    return Error{"setState: got " + std::to_string(positions.size()) + " positions and " +
                 std::to_string(velocities.size()) + " velocities for a cloth of " +
                 std::to_string(n) + " vertices; give one of each per vertex"};
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!positions[i].allFinite() || !velocities[i].allFinite()) {
      return Error{"setState: vertex " + std::to_string(i) +
                   " has a NaN or infinite position or velocity"};
    }
  }
  m_positions.assign(positions.begin(), positions.end());
  m_velocities.assign(velocities.begin(), velocities.end());
  const std::vector<Index>& pins = m_settings.pinnedVertices;
  for (std::size_t k = 0; k < pins.size(); ++k) m_pinStart[k] = m_pinEnd[k] = m_positions[pins[k]];
  m_integrator->reset();  // the previous Δv means nothing for the new state
  m_selfContacts.clear();  // nor the previous pairs
  m_normalsValid = false;
  m_sleep.sleeping = false;
  m_sleep.quietFrames = 0;
  return Status::success();
}

void Cloth::setExternalFields(const Vec3& gravity, const Vec3& wind) {
  m_forces.setExternalFields(gravity, wind);
  m_sleep.wakeRequested = true;
}

void Cloth::constrainContacts(const Vec3Array&, const Vec3Array&, Real, VertexFilter& filter) {
  // The contact pipeline decided the constraints (ContactDetector::constrain); here they become
  // rows of the solve's filter. The rows of the last substep's constraints are freed first.
  for (Index row : m_contactRows) filter.setFree(row);
  m_contactRows.clear();
  for (const SolveConstraint& constraint : m_constraints) {
    const Index row = m_freeVertexMap.row(constraint.vertex - m_firstVertex);
    if (row == kInvalidIndex || filter.kind(row) != ConstraintKind::Free) continue;
    filter.setConstrained(row, constraint.normal, constraint.normalChange * constraint.normal);
    m_contactRows.push_back(row);
  }
}

void Cloth::receiveContactImpulses(std::span<const Real> byRow) {
  // Rows to vertices, impulses to velocity changes: the friction bound of the contacts.
  std::fill(m_solveContactImpulses.begin(), m_solveContactImpulses.end(), Real(0));
  const std::vector<Real>& mass = masses();
  for (Index row = 0; row < Index(byRow.size()); ++row) {
    if (byRow[row] == 0) continue;
    const Index vertex = m_freeVertexMap.vertex(row);
    m_solveContactImpulses[vertex] = byRow[row] / mass[vertex];
  }
}

bool Cloth::beginFrame(Real t, Real frameDt, const StepPlan& plan) {
  // A teleport: the cloth is carried with its pins' best-fit rigid motion before the frame, so
  // it arrives instead of being flung; the pins then move only relative to it. Velocities and
  // the solve's warm start turn with the motion.
  bool teleported = false;
  if (const std::optional<RigidFit> carry = teleportMotion()) {
    for (Vec3& x : m_positions) x = carry->apply(x);
    for (Vec3& start : m_pinStart) start = carry->apply(start);
    if (!carry->translationOnly()) {
      for (Vec3& v : m_velocities) v = carry->rotation * v;
    }
    m_integrator->carryCarriedState(*carry);
    teleported = true;
  }
  m_frameTolerance = plan.cgTolerance > 0 ? plan.cgTolerance : m_settings.solver.cgTolerance;
  m_integrator->setSolveLimits(
      m_frameTolerance,
      plan.cgMaxIterations > 0 ? plan.cgMaxIterations : m_settings.solver.cgMaxIterations);
  m_frameStart = t;
  m_frameLength = frameDt;
  m_frameStartPositions = m_positions;
  m_frameStartVelocities = m_velocities;
  m_integrator->saveCarriedState(m_frameStartCarried);
  m_frameStartJammed = m_jammed;
  m_frameStartSelfContacts = m_selfContacts;
  m_normalsValid = false;
  return teleported;
}

void Cloth::integrate(Real t, Real h, std::span<const SolveConstraint> constraints,
                      Index firstVertex, bool tight, IntegratorReport& report) {
  if (m_settings.solver.tightCgTolerance > 0) {
    // Contact-aware accuracy (SolverSettings::tightCgTolerance): jammed or yanked, solve tighter.
    if (tight) {
      m_integrator->setSolveAccuracy(std::min(m_frameTolerance, m_settings.solver.tightCgTolerance),
                                     PcgStopping::RelativeResidual);
    } else {
      m_integrator->setSolveAccuracy(m_frameTolerance, m_settings.solver.cgStopping);
    }
  }
  m_constraints = constraints;
  m_firstVertex = firstVertex;
  std::fill(m_solveContactImpulses.begin(), m_solveContactImpulses.end(), Real(0));
  // The last substep's self-contact pairs at this substep's start (SelfContactPenalty.h).
  m_solvePairs.clear();
  if (m_selfContactStiffness > 0) {
    const Real reach = kPairReach * m_settings.material.thickness;
    for (const SelfContactFeatures& features : m_selfContacts) {
      // A pair with a pinned vertex is left to the projection (SelfContactPenalty.h).
      if (std::any_of(features.vertices.begin(), features.vertices.end(),
                      [&](Index vertex) { return m_pinnedMask[vertex] != 0; })) {
        continue;
      }
      if (const std::optional<SelfContactPair> pair = selfContactAt(features, m_positions, reach)) {
        m_solvePairs.push_back(*pair);
      }
    }
  }
  m_integrator->step(*this, m_positions, m_velocities, t, h, report);
  m_contactCouplings.clear();
  if (!m_solvePairs.empty()) {
    // Each pair's penalty at the end of the step, k (d₀ − d(x₁)) (backward Euler's force), as the
    // change of its normal relative velocity over the substep: friction's bound.
    const Real k = m_selfContactStiffness;
    const Real thickness = m_settings.material.thickness;
    for (SelfContactPair& pair : m_solvePairs) {
      Vec3 point = Vec3::Zero();
      Real inverseMass = 0;
      for (int j = 0; j < 4; ++j) {
        point += pair.weights[j] * m_positions[pair.vertices[j]];
        inverseMass += pair.weights[j] * pair.weights[j] * m_inverseMasses[pair.vertices[j]];
      }
      const Real overlap = penaltyRestGap(pair.gap, thickness) - pair.normal.dot(point);
      pair.solveImpulse = overlap > 0 ? h * k * overlap * inverseMass : 0;
    }
    std::sort(m_solvePairs.begin(), m_solvePairs.end(),
              [](const SelfContactPair& a, const SelfContactPair& b) {
                return selfContactBefore(a.kind, a.vertices, b.kind, b.vertices);
              });
  }
  m_constraints = {};
  m_normalsValid = false;
}

Real Cloth::selfContactImpulse(ContactKind kind, const std::array<Index, 4>& vertices) const {
  const auto found = std::lower_bound(
      m_solvePairs.begin(), m_solvePairs.end(), 0, [&](const SelfContactPair& pair, int) {
        return selfContactBefore(pair.kind, pair.vertices, kind, vertices);
      });
  if (found == m_solvePairs.end() || found->kind != kind || found->vertices != vertices) return 0;
  return found->solveImpulse;
}

void Cloth::endFrame() {
  m_pinStart = m_pinEnd;  // the next frame starts where this one ended
  m_normalsValid = false;
}

void Cloth::restoreFrameStart() {
  m_positions = m_frameStartPositions;
  m_velocities = m_frameStartVelocities;
  m_integrator->restoreCarriedState(m_frameStartCarried);
  m_jammed = m_frameStartJammed;
  m_selfContacts = m_frameStartSelfContacts;
  m_normalsValid = false;
}

void Cloth::setContactResult(std::span<const Vec3> positions, std::span<const Vec3> velocities) {
  std::copy(positions.begin(), positions.end(), m_positions.begin());
  std::copy(velocities.begin(), velocities.end(), m_velocities.begin());
  m_normalsValid = false;
}

void Cloth::save(SavedState& out) const {
  out.positions = m_positions;
  out.velocities = m_velocities;
  out.pinTargets = m_pinEnd;
  m_integrator->saveCarriedState(out.carried);
  out.sleep = m_sleep;
  out.potentialEnergy = m_lastPotential;
  out.jammed = m_jammed;
  out.selfContacts = m_selfContacts;
}

void Cloth::restore(const SavedState& in) {
  m_positions = in.positions;
  m_velocities = in.velocities;
  m_pinStart = m_pinEnd = in.pinTargets;
  m_integrator->restoreCarriedState(in.carried);
  m_normalsValid = false;
  m_sleep = in.sleep;
  m_lastPotential = in.potentialEnergy;
  m_jammed = in.jammed;
  m_selfContacts = in.selfContacts;
}

const Vec3Array& Cloth::normals() {
  if (m_normalsValid) return m_normals;
  m_normals.assign(m_positions.size(), Vec3::Zero());
  const std::vector<Index>& indices = m_model->indices();
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Vec3& x0 = m_positions[indices[t]];
    // The unnormalised cross product weights each triangle by its area.
    const Vec3 areaNormal = (m_positions[indices[t + 1]] - x0).cross(m_positions[indices[t + 2]] - x0);
    for (int k = 0; k < 3; ++k) m_normals[indices[t + k]] += areaNormal;
  }
  for (Vec3& normal : m_normals) {
    const Real length = normal.norm();
    normal = length > 0 ? Vec3(normal / length) : Vec3(0, 0, 1);
  }
  m_normalsValid = true;
  return m_normals;
}

Real Cloth::maxStrain() const {
  Real strain = 0;
  for (const Edge& edge : m_model->edges()) {
    const Real length = (m_positions[edge.vertices[0]] - m_positions[edge.vertices[1]]).norm();
    strain = std::max(strain, length / edge.restLength - 1);
  }
  return strain;
}

Real Cloth::kineticEnergy() const {
  Real energy = 0;
  const std::vector<Real>& mass = masses();
  for (Index i = 0; i < vertexCount(); ++i) energy += 0.5 * mass[i] * m_velocities[i].squaredNorm();
  return energy;
}

Real Cloth::maxSpeed() const {
  Real speed = 0;
  for (const Vec3& v : m_velocities) speed = std::max(speed, v.norm());
  return speed;
}

}  // namespace weft
