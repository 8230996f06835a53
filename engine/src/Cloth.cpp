#include "Cloth.h"

#include <weft/threading/Profiler.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

namespace weft {
namespace {

// Tolerated growth of the fastest mode per explicit step: a factor e over 10⁶ steps. Small enough
// that an explicit method that passes it does not blow up within any run we make.
constexpr Real kExplicitGrowthPerStep = 1e-6;
// Safety factor on the stable-step estimate (it is an upper bound of ω, but at the rest state).
constexpr Real kStableStepSafety = 0.9;
// A vertex faster than this (m/s) means the integration diverged: no cloth motion comes near
// it (a 250 m/s projectile drags cloth at 250 m/s), while a blown-up explicit step passes it
// within a few substeps.
constexpr Real kDivergedSpeed = 1e4;
// Retries of a failed frame, each with twice the substeps: up to 8 times the planned number.
constexpr int kMaxRetries = 3;
// An edge stretched beyond this strain (l / l_rest − 1) at the end of a frame, and more than at
// the frame start, means the integration diverged: cloth tears long before, and even pins
// teleported by metres leave the implicit solution far below it (the stress suite's scenario 10
// measures the worst physical case). Not the material's strain limit: a health alarm.
constexpr Real kDivergedStrain = 99;
// Kinetic energy at the end of a frame above this multiple of what the frame could supply
// (kinetic + elastic energy at its start, the cloth thrown at the fastest driver's speed, and a
// fall through its own size) means energy came from nowhere: a diverging integration.
constexpr Real kEnergyJumpFactor = 100;
// m/s: a speed scale below which no energy is suspicious (round-off on a cloth at rest).
constexpr Real kQuietSpeed = 0.01;

std::string checkNonNegative(const char* field, Real value, const char* unit) {
  if (std::isfinite(value) && value >= 0) return {};
  std::ostringstream text;
  text << field << " = " << value << " " << unit << ": must be finite and at least 0";
  return text.str();
}

std::string checkPositive(const char* field, Real value, const char* unit) {
  if (std::isfinite(value) && value > 0) return {};
  std::ostringstream text;
  text << field << " = " << value << " " << unit << ": must be finite and greater than 0";
  return text.str();
}

std::string validate(const ClothModel* model, const ClothSettings& settings) {
  if (!model) return "ClothModel is null: build one with ClothModel::grid() or fromMesh()";
  const ClothMaterial& m = settings.material;
  const MassSpringMaterial& s = settings.springs;
  const SolverSettings& solver = settings.solver;
  for (const std::string& problem : {
           checkPositive("material.arealDensity", m.arealDensity, "kg/m²"),
           checkNonNegative("material.warpStretchStiffness", m.warpStretchStiffness, "N/m"),
           checkNonNegative("material.weftStretchStiffness", m.weftStretchStiffness, "N/m"),
           checkNonNegative("material.shearStiffness", m.shearStiffness, "N/m"),
           checkNonNegative("material.bendingStiffness", m.bendingStiffness, "N·m"),
           checkPositive("material.warpRestScale", m.warpRestScale, ""),
           checkPositive("material.weftRestScale", m.weftRestScale, ""),
           checkNonNegative("material.stretchDamping", m.stretchDamping, "N·s/m"),
           checkNonNegative("material.shearDamping", m.shearDamping, "N·s/m"),
           checkNonNegative("material.bendingDamping", m.bendingDamping, "N·m·s"),
           checkNonNegative("material.airDrag", m.airDrag, "N·s/m³"),
           checkPositive("material.thickness", m.thickness, "m"),
           checkNonNegative("material.friction", m.friction, ""),
           checkNonNegative("springs.structuralStiffness", s.structuralStiffness, "N/m"),
           checkNonNegative("springs.shearStiffness", s.shearStiffness, "N/m"),
           checkNonNegative("springs.flexionStiffness", s.flexionStiffness, "N/m"),
           checkNonNegative("springs.structuralDamping", s.structuralDamping, "N·s/m"),
           checkNonNegative("springs.shearDamping", s.shearDamping, "N·s/m"),
           checkNonNegative("springs.flexionDamping", s.flexionDamping, "N·s/m"),
           checkPositive("solver.maxImplicitStep", solver.maxImplicitStep, "s"),
           checkPositive("solver.cgTolerance", solver.cgTolerance, ""),
       }) {
    if (!problem.empty()) return "cloth settings: " + problem;
  }
  if (int(solver.integrator) < int(IntegratorKind::ExplicitEuler) ||
      int(solver.integrator) > int(IntegratorKind::ImplicitEuler)) {
    return "cloth settings: solver.integrator = " + std::to_string(int(solver.integrator)) +
           " is not an IntegratorKind; use one of the enumerators";
  }
  if (settings.forceModel != ForceModel::BaraffWitkin && settings.forceModel != ForceModel::MassSpring) {
    return "cloth settings: forceModel = " + std::to_string(int(settings.forceModel)) +
           " is not a ForceModel; use BaraffWitkin or MassSpring";
  }
  if (solver.cgMaxIterations < 1) return "cloth settings: solver.cgMaxIterations must be at least 1";
  if (solver.newtonIterations < 0) return "cloth settings: solver.newtonIterations must be at least 0";
  if (solver.maxSubsteps < 1) return "cloth settings: solver.maxSubsteps must be at least 1";
  if (!settings.translation.allFinite() || !settings.rotation.allFinite()) {
    return "cloth settings: translation or rotation contains NaN or infinity";
  }
  if (!(settings.rotation.transpose() * settings.rotation).isApprox(Mat3::Identity(), 1e-6) ||
      settings.rotation.determinant() < 0) {
    return "cloth settings: rotation is not a proper rotation matrix (orthonormal, det +1)";
  }
  if (!settings.vertexMasses.empty()) {
    if (settings.vertexMasses.size() != model->vertexCount()) {
      return "cloth settings: vertexMasses has " + std::to_string(settings.vertexMasses.size()) +
             " entries for a model of " + std::to_string(model->vertexCount()) +
             " vertices; give one mass per vertex, or none to use material.arealDensity";
    }
    for (std::size_t i = 0; i < settings.vertexMasses.size(); ++i) {
      if (!(std::isfinite(settings.vertexMasses[i]) && settings.vertexMasses[i] > 0)) {
        std::ostringstream text;
        text << "cloth settings: vertexMasses[" << i << "] = " << settings.vertexMasses[i]
             << " kg: must be finite and greater than 0";
        return text.str();
      }
    }
  }
  std::vector<Index> pins = settings.pinnedVertices;
  std::sort(pins.begin(), pins.end());
  for (std::size_t k = 0; k < pins.size(); ++k) {
    if (pins[k] >= model->vertexCount()) {
      return "cloth settings: pinned vertex " + std::to_string(pins[k]) +
             " does not exist (the model has " + std::to_string(model->vertexCount()) + " vertices)";
    }
    if (k > 0 && pins[k] == pins[k - 1]) {
      return "cloth settings: vertex " + std::to_string(pins[k]) + " is pinned twice; list it once";
    }
  }
  return {};
}

}  // namespace

Result<std::unique_ptr<Cloth>> Cloth::create(std::shared_ptr<const ClothModel> model,
                                             const ClothSettings& settings,
                                             const WorldSettings& world, TaskSystem* tasks) {
  if (std::string problem = validate(model.get(), settings); !problem.empty()) return Error{problem};
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
                                  world.gravity, world.wind, StiffnessMode::Definite},
               std::move(masses), tasks) {
  const std::vector<std::array<Index, 2>> pairs = m_forces.coupledPairs();
  m_matrix.build(m_model->vertexCount(), pairs);
  m_forces.bindMatrix(m_matrix);
  m_integrator = Integrator::create(settings.solver.integrator, settings.solver);

  const Index n = m_model->vertexCount();
  m_positions.resize(n);
  for (Index i = 0; i < n; ++i) {
    m_positions[i] = settings.rotation * m_model->restPositions()[i] + settings.translation;
  }
  m_velocities.assign(n, Vec3::Zero());
  m_savedPositions = m_positions;
  m_savedVelocities = m_velocities;

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
  m_pinStart.resize(pins.size());
  for (std::size_t k = 0; k < pins.size(); ++k) m_pinStart[k] = m_positions[pins[k]];
  m_pinEnd = m_pinStart;

  m_inverseMasses.resize(n);
  const std::vector<Real>& mass = m_forces.masses();
  for (Index i = 0; i < n; ++i) m_inverseMasses[i] = m_pinnedMask[i] ? 0 : 1 / mass[i];
  if (settings.selfCollision) m_selfCollision = std::make_unique<SelfCollision>(*m_model, tasks);
  estimateStiffestMode();
}

void Cloth::estimateStiffestMode() {
  // A(h) = M − h D − h² K with D = ∂f/∂v, K = ∂f/∂x, so from h = ±1:
  //   K = M − (A(1) + A(−1)) / 2,   D = (A(−1) − A(1)) / 2.
  // Gershgorin on M^{-1/2}(−K)M^{-1/2} bounds ω², and on M^{-1/2}(−D)M^{-1/2} the damping rate.
  const Index n = vertexCount();
  Vec3Array f, product, zero(n, Vec3::Zero());
  BlockSparseMatrix plus = m_matrix, minus = m_matrix;
  m_forces.assemble(m_positions, zero, 1.0, plus, f, zero, product);
  m_forces.assemble(m_positions, zero, -1.0, minus, f, zero, product);
  std::vector<bool> pinned(n, false);
  for (Index p : m_pinnedSorted) pinned[p] = true;
  const std::vector<Real>& mass = masses();
  Real omegaSquared = 0, dampingRate = 0;
  for (Index row = 0; row < n; ++row) {
    if (pinned[row]) continue;
    Real stiffnessSum = 0, dampingSum = 0;
    for (Index slot = plus.rowBegin(row); slot < plus.rowEnd(row); ++slot) {
      const Index column = plus.column(slot);
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

Index Cloth::plannedSubsteps(Real frameDt, bool* predictedUnstable) const {
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
  } else if (!implicit && frameDt / substeps > m_stableStep && predictedUnstable) {
    *predictedUnstable = true;
  }
  return substeps;
}

Real Cloth::computeForces(const Vec3Array& x, const Vec3Array& v, Real, Vec3Array& f) {
  return m_forces.computeForces(x, v, f);
}

Real Cloth::linearize(const Vec3Array& x, const Vec3Array& v, Real, Real h, Vec3Array& f,
                      const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity) {
  return m_forces.assemble(x, v, h, m_matrix, f, velocityForProduct, stiffnessTimesVelocity);
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
  m_normalsValid = false;
  return Status::success();
}

void Cloth::constrainContacts(const Vec3Array& x, const Vec3Array& v, Real h,
                              VertexFilter& filter) {
  m_colliderResponse.constrain(m_colliders, x, v, h, m_settings.material.thickness, m_pinnedMask,
                               filter);
}

HealthFailure Cloth::runSubsteps(Real t, Real frameDt, Index substeps,
                                 std::span<ColliderFrame> colliders, ClothFrameReport& report) {
  const Real h = frameDt / substeps;
  const RigidMotion* frameStart = m_frameStartMotions.data();
  for (Index substep = 0; substep < substeps; ++substep) {
    IntegratorReport substepReport;
    for (std::size_t k = 0; k < colliders.size(); ++k) {
      colliders[k].start = advanceMotion(frameStart[k], substep * h);
      colliders[k].end = advanceMotion(frameStart[k], (substep + 1) * h);
      (void)setMotion(*colliders[k].shape, colliders[k].end);
    }
    m_colliders = colliders;
    if (!colliders.empty() || m_selfCollision) {
      m_stepStartPositions = m_positions;
      m_stepStartVelocities = m_velocities;
    }
    m_integrator->step(*this, m_positions, m_velocities, t + substep * h, h, substepReport);
    if (!colliders.empty()) {
      const ColliderResponseReport contact = m_colliderResponse.resolve(
          colliders, m_stepStartPositions, m_stepStartVelocities, m_settings.material.thickness,
          m_pinnedMask, m_positions, m_velocities);
      report.contacts = contact.contacts;
    }
    if (m_selfCollision) {
      const SelfCollisionReport self = m_selfCollision->resolve(
          m_stepStartPositions, h, m_settings.material.thickness, m_settings.material.friction,
          m_inverseMasses, m_positions, m_velocities);
      report.selfCollision.proximityContacts += self.proximityContacts;
      report.selfCollision.impacts += self.impacts;
      report.selfCollision.impactZones += self.impactZones;
      report.selfCollision.frozenVertices += self.frozenVertices;
    }
    report.integrator.linearSolves += substepReport.linearSolves;
    report.integrator.cgIterations += substepReport.cgIterations;
    report.integrator.cgResidual = substepReport.cgResidual;
    report.integrator.cgConverged = report.integrator.cgConverged && substepReport.cgConverged;
    report.integrator.potentialEnergy = substepReport.potentialEnergy;
    if (substep == 0) m_frameStartPotential = substepReport.potentialEnergy;
    report.integrator.assemblyMs += substepReport.assemblyMs;
    report.integrator.solveMs += substepReport.solveMs;
    // A cheap health check each substep: a NaN spreads through the whole mesh within one solve,
    // and a diverging explicit method passes any physical speed within a few substeps.
    WEFT_PROFILE_ZONE("health");
    bool finite = true, slow = true;
    for (const Vec3& x : m_positions) finite = finite && x.allFinite();
    for (const Vec3& v : m_velocities) {
      finite = finite && v.allFinite();
      slow = slow && v.squaredNorm() < kDivergedSpeed * kDivergedSpeed;
    }
    if (!finite) return HealthFailure::NonFinite;
    if (!slow) return HealthFailure::Speed;
  }
  return HealthFailure::None;
}

HealthFailure Cloth::checkFrameHealth(Real startStrain, Real startKinetic) const {
  const Real strain = maxStrain();
  if (strain > kDivergedStrain && strain > startStrain) return HealthFailure::Strain;
  // The energy the frame could give the cloth: what it had (kinetic, and elastic: the reported
  // potential minus gravity's part, −Σ m g·x), the whole cloth thrown at the fastest driver's
  // speed (pins, collider surfaces, wind), and a free fall through its own size.
  const std::vector<Real>& mass = masses();
  const Vec3& gravity = m_forces.settings().gravity;
  Real totalMass = 0, gravityPotential = 0;
  for (Index i = 0; i < vertexCount(); ++i) {
    totalMass += mass[i];
    gravityPotential -= mass[i] * gravity.dot(m_savedPositions[i]);
  }
  const Real elastic = std::max<Real>(0, m_frameStartPotential - gravityPotential);
  const Real size = m_model->characteristicLength();
  Real driverSpeed = std::max(kQuietSpeed, m_forces.settings().wind.norm());
  for (std::size_t k = 0; k < m_pinEnd.size(); ++k) {
    driverSpeed = std::max(driverSpeed, (m_pinEnd[k] - m_pinStart[k]).norm() / m_frameLength);
  }
  for (const RigidMotion& motion : m_frameStartMotions) {
    const Real reach = (motion.pose.position - m_savedPositions[0]).norm() + size;
    driverSpeed = std::max(driverSpeed, motion.linearVelocity.norm() +
                                            motion.angularVelocity.norm() * reach);
  }
  const Real available = startKinetic + elastic +
                         0.5 * totalMass * (driverSpeed * driverSpeed + 2 * gravity.norm() * size);
  if (kineticEnergy() > kEnergyJumpFactor * available) return HealthFailure::EnergyJump;
  return HealthFailure::None;
}

void Cloth::save(SavedState& out) const {
  out.positions = m_positions;
  out.velocities = m_velocities;
  out.pinTargets = m_pinEnd;
  m_integrator->saveCarriedState(out.carried);
}

void Cloth::restore(const SavedState& in) {
  m_positions = in.positions;
  m_velocities = in.velocities;
  m_pinStart = m_pinEnd = in.pinTargets;
  m_integrator->restoreCarriedState(in.carried);
  m_normalsValid = false;
}

ClothFrameReport Cloth::stepFrame(Real t, Real frameDt, std::span<ColliderFrame> colliders) {
  ClothFrameReport report;
  bool predictedUnstable = false;
  Index substeps = plannedSubsteps(frameDt, &predictedUnstable);
  if (predictedUnstable) report.status |= StepStatus::Unstable;

  m_savedPositions = m_positions;
  m_savedVelocities = m_velocities;
  const Real startStrain = maxStrain();
  const Real startKinetic = kineticEnergy();
  m_frameStart = t;
  m_frameLength = frameDt;
  // The friction of a pair is the geometric mean of the two coefficients.
  for (ColliderFrame& collider : colliders) {
    collider.friction = std::sqrt(std::max<Real>(0, collider.friction) * m_settings.material.friction);
  }
  m_frameStartMotions.clear();  // keeps its capacity: no allocation once colliders are known
  for (const ColliderFrame& collider : colliders) m_frameStartMotions.push_back(collider.start);

  // Health monitor: a frame that ends non-finite or diverging (too fast, too stretched, energy
  // from nowhere) is undone and retried with twice as many substeps, up to kMaxRetries times; if
  // it still fails, the cloth stays where the frame started. Either way the caller hears of it,
  // with the check that failed, and never sees a NaN.
  for (int attempt = 0;; ++attempt) {
    report.substeps = substeps;
    report.integrator = IntegratorReport{};
    HealthFailure failure = runSubsteps(t, frameDt, substeps, colliders, report);
    if (failure == HealthFailure::None) {
      WEFT_PROFILE_ZONE("health");
      failure = checkFrameHealth(startStrain, startKinetic);
    }
    if (failure == HealthFailure::None) break;
    report.healthFailure = failure;
    m_positions = m_savedPositions;
    m_velocities = m_savedVelocities;
    m_integrator->reset();  // the failed attempt's Δv is no warm start
    report.status |= StepStatus::Unstable;
    if (attempt == kMaxRetries) {
      report.status |= StepStatus::RolledBack;
      break;
    }
    report.status |= StepStatus::RetriedWithSmallerStep;
    substeps *= 2;
  }
  m_colliders = {};
  if (!report.integrator.cgConverged) report.status |= StepStatus::SolverNotConverged;
  m_pinStart = m_pinEnd;  // next frame starts where this one ended
  m_normalsValid = false;
  return report;
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
