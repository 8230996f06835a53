#include "Cloth.h"
#include "solver/MulticolorOrdering.h"

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
// How far (in contact thicknesses) the triangles under a self-collision BVH leaf may move before
// the leaf's box is refit. Larger skips more refits of a slowly moving cloth and makes leaf boxes
// looser (the self query prunes less; its results never change). 2 % of the thickness (60 µm on
// the curtain) is far above the creep of cloth at rest and far below anything that loosens the
// boxes measurably: on a strip folded on the floor it keeps 57 % of the nodes per frame against
// 58 % for half a thickness, and half a thickness was measured no faster overall.
constexpr Real kBvhRefitMotionPerThickness = 0.02;
// A vertex faster than this (m/s) means the integration diverged: no cloth motion comes near
// it (a 250 m/s projectile drags cloth at 250 m/s), while a blown-up explicit step passes it
// within a few substeps.
constexpr Real kDivergedSpeed = kMaxSpeed;
// Retries of a failed frame, each with twice the substeps: up to 8 times the planned number.
constexpr int kMaxRetries = 3;
// A sleeping cloth watches colliders within this distance (m) beyond its contact thickness: far
// enough that a collider cannot reach it unseen within a frame unless it moves (and a moving
// collider near it wakes it anyway), near enough that distant traffic leaves it asleep.
constexpr Real kWakeMargin = 0.01;
// Rounds of strain limiting in contact and collision response after the first collision passes
// (Cloth::limitStrainInContact); each ends with the collisions, which keep the last word. Most
// calls need one round or none (the curtain: 1.15 rounds per call); with 3 rounds (and 64
// limiter iterations) the 250 m/s sphere and the curtain at 1/15 s steps of the stress suite
// still ended over the limit (0.120, 0.112), with 6 within it (0.107, 0.102). Every round that
// moved vertices runs the self-collision pass again: skipping it after rounds that moved no
// vertex a tenth of the thickness was tried, and let a crossing through (stress scene 10) and
// left the jammed layers of scene 7 at strain 2.3 instead of 0.26.
constexpr int kContactLimitPasses = 6;
// A face the last face pass left on a body is constrained in the next solve while it rests
// within this fraction of the contact thickness beyond its reach (Cloth::constrainFaceCorners),
// as ColliderResponse's pressed shell holds a resting vertex.
constexpr Real kFacePressedShell = 0.01;
// Joint projection (Cloth::limitStrainInContact in contact with colliders; ColliderProjection.h):
// the limiter's iterations per round, the rounds, and the last projection's edge tolerance (a
// fraction of StrainLimitSettings::tolerance). Measured on stress scene 7 (three sheets through
// a ring of capsules) over the layers shifted by 0, 1e-9, 1e-7, 1e-5 m, with every self-contact
// held: 64 iterations and 6 rounds, the self-collision pass last, 0.13 ... 0.16 (11 x 11); 256
// and 12, 0.12 ... 0.18 at 16 x 16; with a last projection after 6 rounds, 0.101 but 2 to 10
// intersecting pairs at 16 x 16 (the projection moves what the rounds left far, past pairs that
// were not in contact); after 12 rounds of 256, 0.101 and none in the first version, then 4
// pairs in one of the four draws once the face contacts' skipped point was fixed; after 24
// rounds 0.101 and none at 11 x 11 and 16 x 16 (the scene 8 % slower than with 12). The
// self-collision pass after the last projection instead: no crossing, but 0.101 ... 0.109 and
// 0.16 ... 0.22 at 16 x 16. Rounds run only while a substep has not settled.
constexpr int kJointProjectionIterations = 256;
constexpr int kJointProjectionRounds = 24;
constexpr Real kLastProjectionTolerance = 0.5;
// The vertices a joint projection keeps out of a collider: those within the thickness plus this
// fraction of the mean edge length of it when the round starts (ColliderProjection::prepare).
constexpr Real kProjectionMarginPerEdge = 0.5;
// kHeldContactMassRatio (StrainLimiting.h, shared with ClothClothCollision): a self-contact is
// held inside the strain limiter (one-sided, StrainLimiter::applyInContact's `separations`) when
// one of its vertices is more than this many times heavier than another.
// Between comparable masses the rounds above converge: each collision pass shares its correction
// evenly, and the limiter pulls the rest back. Under a much heavier side the light one takes
// almost all of every collision correction (a fraction m_light / m_heavy goes to the heavy side
// per round), so the rounds cannot lift a weight off a light sheet: stress scene 9 (0.5 kg pads,
// 31 g vertices, on 0.7 g sheet vertices) ended at strain 8.1; holding its pairs, 0.103. Holding
// every self-contact was measured too: scene 9 the same, scene 7 0.285 instead of 0.27 (a new
// draw of a jammed scene), but the crumpled cloth of stress scene 10 kept folds caught: with its
// teleport distance perturbed by 0, 1e-12, 1e-9, 1e-6, 1e-3 and 3e-3 m, 1 of 6 runs recovered
// (0 to 4 of 6 for variants that held fewer pairs), against 14 of 18 without holds (the scene's
// notes). So comparable masses are left to the rounds. An order of magnitude is past the mass
// spread of one area-weighted fabric (a grid corner carries a sixth of an interior vertex's).

// A point farther than this from a box that holds a shape is farther than `thickness` from the
// shape, with room for the round-off of the distance queries: skipping the narrow phase of such a
// collider changes no bit.
Real contactMargin(Real thickness) { return thickness * (1 + 1e-6) + 1e-9; }

// True when some point of `points` may lie within `margin` of the shape.
bool colliderNear(const Shape& shape, const Aabb& points, Real margin) {
  if (points.isEmpty()) return false;
  Aabb box = bounds(shape);
  box.inflate(margin);
  if (!box.overlaps(points)) return false;
  if (const Plane* plane = std::get_if<Plane>(&shape)) {
    // A tilted half-space has an unbounded box; its signed distance is linear, so the corners of
    // the points' box bound it from below.
    Real nearest = std::numeric_limits<Real>::infinity();
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 point((corner & 1) ? points.max.x() : points.min.x(),
                       (corner & 2) ? points.max.y() : points.min.y(),
                       (corner & 4) ? points.max.z() : points.min.z());
      nearest = std::min(nearest, plane->queryPoint(point).distance);
    }
    return nearest < margin;
  }
  return true;
}
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
// The implicit solve's self-contact pairs (SolverSettings::selfContactStiffness) are looked for
// within this many thicknesses at the step start; a pair's penalty acts below one thickness
// only, so the pairs between one and two are candidates the solve may push into contact within
// the step (ImplicitEuler's active set turns them on then). Measured on the corner crumple (15
// runs: 5 solver tolerances × 3 drop heights, stiffness 1, 2 active-set passes): 1.5, 2 and 3
// thicknesses settled 8, 10 and 10 of 15 (within the draw of a chaotic scene); 2 catches pairs
// that approach by up to a thickness in a step. The search costs one proximity query per
// substep; the self-collision pass then queries its own (one thickness) again.
constexpr Real kSelfContactSearch = 2;

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

// 0 and +infinity both mean "no limit"; NaN and negatives are mistakes.
std::string checkStrainLimit(Real value) {
  if (value >= 0) return {};
  std::ostringstream text;
  text << "material.strainLimit = " << value
       << " (strain l / l_rest - 1): must be at least 0; use 0 or infinity to turn strain "
          "limiting off";
  return text.str();
}

// A level at or above which a substep is hard (SolverSettings::tightPinTravel,
// tightSelfContactDensity): any positive value, +infinity included (never hard); 0, negatives and
// NaN are mistakes.
std::string checkHardSubstepThreshold(const char* field, Real value, const char* unit,
                                      const char* infinityMeans) {
  if (value > 0) return {};
  std::ostringstream text;
  text << field << " = " << value << " (" << unit << "): must be greater than 0 (infinity = "
       << infinityMeans << "; tightCgTolerance = 0 turns the tightening off)";
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
           checkStrainLimit(m.strainLimit),
           checkNonNegative("springs.structuralStiffness", s.structuralStiffness, "N/m"),
           checkNonNegative("springs.shearStiffness", s.shearStiffness, "N/m"),
           checkNonNegative("springs.flexionStiffness", s.flexionStiffness, "N/m"),
           checkNonNegative("springs.structuralDamping", s.structuralDamping, "N·s/m"),
           checkNonNegative("springs.shearDamping", s.shearDamping, "N·s/m"),
           checkNonNegative("springs.flexionDamping", s.flexionDamping, "N·s/m"),
           checkPositive("solver.maxImplicitStep", solver.maxImplicitStep, "s"),
           checkPositive("solver.cgTolerance", solver.cgTolerance, ""),
           checkNonNegative("solver.selfContactStiffness", solver.selfContactStiffness,
                            "(times the stretch stiffness; 0 turns it off)"),
           checkNonNegative("solver.maxPinTravelPerSubstep", solver.maxPinTravelPerSubstep,
                            "mean edge lengths (0 = no limit)"),
           checkNonNegative("solver.pinTeleportDistance", solver.pinTeleportDistance,
                            "cloth sizes (0 = pins never teleport the cloth)"),
           checkNonNegative("solver.pinTeleportAngle", solver.pinTeleportAngle,
                            "rad (0 = a turn of the pins never teleports the cloth)"),
           checkHardSubstepThreshold("solver.tightPinTravel", solver.tightPinTravel,
                                     "mean edge lengths per substep",
                                     "pins never make a substep hard"),
           checkHardSubstepThreshold("solver.tightSelfContactDensity",
                                     solver.tightSelfContactDensity, "self-contacts per vertex",
                                     "self-contact never makes a substep hard"),
       }) {
    if (!problem.empty()) return "cloth settings: " + problem;
  }
  if (int(solver.integrator) < int(IntegratorKind::ExplicitEuler) ||
      int(solver.integrator) > int(IntegratorKind::Bdf2)) {
    return "cloth settings: solver.integrator = " + std::to_string(int(solver.integrator)) +
           " is not an IntegratorKind; use one of the enumerators";
  }
  if (settings.forceModel != ForceModel::BaraffWitkin && settings.forceModel != ForceModel::MassSpring) {
    return "cloth settings: forceModel = " + std::to_string(int(settings.forceModel)) +
           " is not a ForceModel; use BaraffWitkin or MassSpring";
  }
  if (!(solver.tightCgTolerance >= 0 && solver.tightCgTolerance < 1)) {
    std::ostringstream text;
    text << "cloth settings: solver.tightCgTolerance = " << solver.tightCgTolerance
         << " (relative residual): must be at least 0 and below 1 (0 = hard substeps are not "
            "tightened)";
    return text.str();
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
  buildSystemRows();
  m_pinStart.resize(pins.size());
  for (std::size_t k = 0; k < pins.size(); ++k) m_pinStart[k] = m_positions[pins[k]];
  m_pinEnd = m_pinStart;
  for (const Edge& edge : m_model->edges()) m_meanEdgeLength += edge.restLength;
  if (!m_model->edges().empty()) m_meanEdgeLength /= Real(m_model->edges().size());

  m_inverseMasses.resize(n);
  const std::vector<Real>& mass = m_forces.masses();
  for (Index i = 0; i < n; ++i) m_inverseMasses[i] = m_pinnedMask[i] ? 0 : 1 / mass[i];
  if (settings.selfCollision) {
    m_selfCollision = std::make_unique<SelfCollision>(*m_model, tasks);
    m_foldCulling = std::make_unique<FoldCulling>(*m_model);
    // Parts of the cloth that moved less than this since their boxes were last refit keep them
    // (the self-collision results are the same bits either way; see Bvh.h).
    m_selfCollision->setRefitSkipping(
        world.skipUnneededStages ? kBvhRefitMotionPerThickness * settings.material.thickness : -1);
  }
  const Real strainLimit = settings.material.strainLimit;
  if (strainLimit > 0 && std::isfinite(strainLimit)) {
    m_strainLimiter = std::make_unique<StrainLimiter>(m_model->edges(), n);
    m_strainLimitSettings.limit = strainLimit;
    m_contactHolds.normals.assign(n, Vec3::Zero());
    m_contactHolds.fixed.assign(n, 0);
    m_heldInverseMasses.assign(n, 0);
    m_freeContactNormals.assign(n, Vec3::Zero());
    m_jointLimitSettings = m_strainLimitSettings;
    m_jointLimitSettings.maxIterations = kJointProjectionIterations;
    // Only a cloth whose masses spread beyond kHeldContactMassRatio can have a self-contact the
    // limiter holds; the others do not pay for recording them.
    if (m_selfCollision && !mass.empty()) {
      const auto [lightest, heaviest] = std::minmax_element(mass.begin(), mass.end());
      m_massesNeedSeparations = *heaviest > kHeldContactMassRatio * *lightest;
      m_selfCollision->setRecordSeparations(m_massesNeedSeparations);
    }
  }
  m_skipStages = world.skipUnneededStages;
  // Self-contacts in the implicit solve: k = selfContactStiffness × the stretch stiffness (N/m).
  if (m_selfCollision && settings.solver.integrator == IntegratorKind::ImplicitEuler) {
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
  const std::vector<std::array<Index, 2>> pairs = m_forces.coupledPairs();
  std::vector<std::array<Index, 2>> rowPairs;
  rowPairs.reserve(pairs.size());
  for (const auto& [a, b] : pairs) {
    const Index rowA = m_freeVertexMap.row(a), rowB = m_freeVertexMap.row(b);
    if (rowA != kInvalidIndex && rowB != kInvalidIndex) rowPairs.push_back({rowA, rowB});
  }
  m_matrix.build(m_freeVertexMap.rowCount(), rowPairs);
  if (m_vertexColors.size() != n) {
    m_vertexColors = MulticolorOrdering::colorVertices(n, m_forces.potentialCoupledPairs());
  }
  m_rowColors.resize(m_freeVertexMap.rowCount());
  for (Index row = 0; row < m_freeVertexMap.rowCount(); ++row) {
    m_rowColors[row] = m_vertexColors[m_freeVertexMap.vertex(row)];
  }
  m_pinnedCoupling.build(m_freeVertexMap, pairs);
  m_forces.bindMatrix(m_matrix, m_freeVertexMap, m_pinnedCoupling);
  m_contactFilter.resize(m_freeVertexMap.isIdentity() ? 0 : n);
  m_contactRows.clear();
  m_contactRows.reserve(m_freeVertexMap.rowCount());
  m_faceConstrainedCorners.reserve(vertexCount());  // a corner is constrained once at most
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
  m_stages.bendingAssemblies += m_forces.evaluatesBending();
  return m_forces.computeForces(x, v, f);
}

Real Cloth::linearize(const Vec3Array& x, const Vec3Array& v, Real, Real h, Vec3Array& f,
                      const Vec3Array& velocityForProduct, Vec3Array& stiffnessTimesVelocity) {
  m_stages.bendingAssemblies += m_forces.evaluatesBending();
  m_stages.dampingJacobians += m_forces.formsDampingJacobians();
  const Real energy = m_forces.assemble(x, v, h, m_matrix, f, velocityForProduct,
                                        stiffnessTimesVelocity, &m_pinnedCoupling);
  addSelfContactTerms(x, h, f, velocityForProduct, stiffnessTimesVelocity);
  return energy;
}

void Cloth::addSelfContactTerms(const Vec3Array& x, Real h, Vec3Array& f,
                                const Vec3Array& velocityForProduct,
                                Vec3Array& stiffnessTimesVelocity) {
  // The penalty ½ k (d₀ − d)² of every pair found at the step start (n and w frozen), evaluated
  // at x, as a coupling of the solve (ContactCoupling.h): h² k JᵀJ, its normal force and its
  // ∂f/∂x·v = −k Jᵀ(J v). The integrator adds the forces to the right-hand side itself, because
  // it releases a pair whose force would pull at the end of the step (one-sided contact). Every
  // pair gives a term (zero when apart at x), so the terms stay in pair order across the
  // linearisations of a step. The penalty's energy is not part of the reported potential (a
  // device of the solve; the self-collision pass after it keeps the contacts).
  (void)f;
  (void)stiffnessTimesVelocity;
  m_contactCouplings.clear();  // keeps its capacity
  const Real stiffness = m_selfContactStiffness;
  const Real thickness = m_settings.material.thickness;
  for (const SeparationHold& pair : m_selfContactPairs) {
    // The spring's force k (d₀ − d) extended linearly beyond d₀ (negative: it would pull): the
    // integrator keeps a term only while its force at the end of the step pushes.
    const std::array<Vec3, 4> corners{x[pair.vertices[0]], x[pair.vertices[1]],
                                      x[pair.vertices[2]], x[pair.vertices[3]]};
    Vec3 relative = Vec3::Zero();
    for (int k = 0; k < 4; ++k) relative += pair.weights[k] * velocityForProduct[pair.vertices[k]];
    ContactCoupling term{pair.vertices, pair.weights, pair.normal, h * h * stiffness, 0, 0};
    term.force = contactPenalty(corners, pair.weights, pair.normal, thickness, stiffness).force;
    term.stiffnessTimesVelocity = -stiffness * pair.normal.dot(relative);
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
  m_wakeRequested = true;
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
  m_sleeping = false;
  m_quietFrames = 0;
  return Status::success();
}

void Cloth::setExternalFields(const Vec3& gravity, const Vec3& wind) {
  m_forces.setExternalFields(gravity, wind);
  m_wakeRequested = true;
}

void Cloth::selectNearColliders(std::span<const ColliderFrame> colliders, const Aabb& points,
                                const Aabb* carriedStart) {
  m_nearColliders.clear();
  const Real margin = contactMargin(m_settings.material.thickness);
  for (const ColliderFrame& collider : colliders) {
    bool near = !m_skipStages;
    if (!near) {
      // The response also follows each vertex's start point carried with the body; for a body
      // that did not move in the step that is the start point itself (to round-off).
      const bool moved = !(collider.start.pose.position == collider.end.pose.position &&
                           collider.start.pose.rotation.coeffs() == collider.end.pose.rotation.coeffs());
      Aabb box = points;
      if (carriedStart && !moved) box.expand(*carriedStart);
      if (carriedStart && moved) {
        for (Index i = 0; i < vertexCount(); ++i) {
          if (!m_pinnedMask[i]) {
            box.expand(collider.end.pose.toWorld(collider.start.pose.toLocal(m_stepStartPositions[i])));
          }
        }
      }
      near = colliderNear(*collider.shape, box, margin);
    }
    if (near) {
      m_nearColliders.push_back(collider);
      ++m_stages.colliderNarrowPhases;
    } else {
      ++m_stages.colliderNarrowPhasesSkipped;
    }
  }
}

void Cloth::constrainContacts(const Vec3Array& x, const Vec3Array& v, Real h,
                              VertexFilter& filter) {
  // The constraint pass tests the paths from the start points x (carried with each body) to
  // the predicted positions x + h v of free vertices.
  Aabb predicted = Aabb::empty(), start = Aabb::empty();
  if (m_skipStages && !m_colliders.empty()) {
    for (Index i = 0; i < vertexCount(); ++i) {
      if (m_pinnedMask[i]) continue;
      predicted.expand(Vec3(x[i] + h * v[i]));
      start.expand(x[i]);
    }
  }
  selectNearColliders(m_colliders, predicted, &start);
  // The contacts are gathered by vertex: straight into the solve's filter when its rows are the
  // vertices; else, pins being removed from the solve, into m_contactFilter and then copied (bit
  // for bit) into the rows. Pinned vertices are never constrained, so every constrained vertex
  // has a row.
  const bool rowsAreVertices = m_freeVertexMap.isIdentity();
  VertexFilter& byVertex = rowsAreVertices ? filter : m_contactFilter;
  // The face corners first: ColliderResponse frees only the vertices it constrained itself.
  for (Index corner : m_faceConstrainedCorners) byVertex.setFree(corner);
  m_colliderResponse.constrain(m_nearColliders, x, v, h, m_settings.material.thickness,
                               m_pinnedMask, byVertex);
  constrainFaceCorners(x, v, h, byVertex);
  if (rowsAreVertices) return;
  for (Index row : m_contactRows) filter.setFree(row);
  m_contactRows.clear();
  if (m_contactFilter.constrainedVertexCount() == 0) return;
  for (Index i = 0; i < vertexCount(); ++i) {
    if (m_contactFilter.kind(i) == ConstraintKind::Free) continue;
    const Index row = m_freeVertexMap.row(i);
    if (row == kInvalidIndex) continue;
    filter.copyConstraint(row, m_contactFilter, i);
    m_contactRows.push_back(row);
  }
}

void Cloth::constrainFaceCorners(const Vec3Array& x, const Vec3Array& v, Real h,
                                 VertexFilter& filter) {
  // A face resting on a body thinner than its triangles (a towel on a rod) carries the cloth's
  // weight on the face alone: its corners are clear of the body, so the vertex constraints do
  // not hold them, and the solve let the cloth sink into the body by up to h² g a step (2.7 mm at
  // 1/60 s) for the face pass to push it back out. Those pushes, distributed by barycentric
  // weight over a triangulation whose diagonals all run one way, carried the towel along the rod
  // at a steady 9.5 cm/s (the floor that gave way in the solve, for faces; ColliderResponse.h).
  // Here each such face's corners are constrained along its contact normal so that the face
  // point ends the step at its reach (one that rests a little clear comes down onto it, as a
  // pressed vertex does); a constraint that pulls is released by the solve like a vertex's.
  m_faceConstrainedCorners.clear();
  if (!m_settings.faceContacts || m_colliders.empty()) return;
  const Real shell = kFacePressedShell * m_settings.material.thickness;
  for (const SeparationHold& hold : m_faceContacts.holds()) {
    Vec3 point = Vec3::Zero(), velocity = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      point += hold.weights[k] * x[hold.vertices[k]];
      velocity += hold.weights[k] * v[hold.vertices[k]];
    }
    const Real gap = hold.normal.dot(point) - hold.separation;  // m, ≥ 0: at or beyond the reach
    if (gap > shell && gap + h * hold.normal.dot(velocity) > 0) continue;  // stays clear
    const Real speed = -gap / h;  // m/s along the normal that ends the step at the reach
    for (int k = 0; k < 3; ++k) {
      const Index corner = hold.vertices[k];
      if (!(hold.weights[k] > 0) || m_pinnedMask[corner] ||
          filter.kind(corner) != ConstraintKind::Free) {
        continue;
      }
      filter.setConstrained(corner, hold.normal,
                            (speed - hold.normal.dot(v[corner])) * hold.normal);
      m_faceConstrainedCorners.push_back(corner);
    }
  }
}

void Cloth::receiveContactImpulses(std::span<const Real> byRow) {
  // Rows to vertices, impulses to velocity changes: what ColliderResponse::resolve takes.
  std::fill(m_solveContactImpulses.begin(), m_solveContactImpulses.end(), Real(0));
  if (byRow.empty()) return;
  const std::vector<Real>& mass = masses();
  for (Index row = 0; row < Index(byRow.size()); ++row) {
    if (byRow[row] == 0) continue;
    const Index vertex = m_freeVertexMap.vertex(row);
    m_solveContactImpulses[vertex] = byRow[row] / mass[vertex];
  }
}

void Cloth::resolveSelfCollision(Real h, std::span<ColliderFrame> colliders,
                                 ClothFrameReport& report) {
  ++m_stages.selfCollisionPasses;
  const SelfCollisionReport self = m_selfCollision->resolve(
      m_stepStartPositions, h, m_settings.material.thickness, m_settings.material.friction,
      m_inverseMasses, m_positions, m_velocities, colliders);
  report.selfCollision.proximityContacts += self.proximityContacts;
  report.selfCollision.impacts += self.impacts;
  report.selfCollision.impactZones += self.impactZones;
  report.selfCollision.frozenVertices += self.frozenVertices;
  const Bvh::RefitCounts refits = m_selfCollision->takeRefitCounts();
  m_stages.bvhNodesRefit += refits.refitNodes;
  m_stages.bvhNodesSkipped += refits.skippedNodes;
}

Index Cloth::resolveFaceContacts(Real frictionStep) {
  if (!m_settings.faceContacts) return 0;
  const ColliderFaceReport faces = m_faceContacts.resolve(
      m_nearColliders, m_model->triangles(), m_stepStartPositions, m_inverseMasses,
      m_settings.material.thickness, m_positions, m_velocities, frictionStep > 0, frictionStep,
      m_solveContactImpulses);
  // Pushing a face out of one body can move its corners into another (a sheet pressed between
  // a ring and a pusher): the vertices keep the last word.
  if (faces.contacts > 0) keepVerticesOutOfColliders();
  return faces.contacts;
}

void Cloth::keepVerticesOutOfColliders() {
  // Without friction, which the substep's first pass took; with the holds, so that a vertex put
  // on a surface is held there.
  std::span<const ColliderFrame> colliders = m_nearColliders;
  const Vec3Array* from = &m_stepStartPositions;
  if (m_keepOutFromProjection) {
    // After a joint projection (limitStrainInContact): the paths from where the projection
    // left each vertex, the bodies held at their end pose. The first pass already followed each
    // vertex from the step start with the bodies' motion, and the projection followed it from
    // there in small steps (ColliderProjection); the chord from the step start to a vertex the
    // projection moved round a body can cut the body although neither end is in it, and the
    // pass then sent the vertex back to where the chord met the surface (stress scene 7: strain
    // 0.40 right after a projection that left 0.101).
    m_stillColliders.assign(m_nearColliders.begin(), m_nearColliders.end());
    for (ColliderFrame& collider : m_stillColliders) collider.start = collider.end;
    colliders = m_stillColliders;
    from = &m_projectedPositions;
  }
  (void)m_colliderResponse.resolve(colliders, *from, m_stepStartVelocities,
                                   m_settings.material.thickness, m_pinnedMask, m_positions,
                                   m_velocities, m_strainLimiter ? &m_contactHolds : nullptr,
                                   /*friction=*/false);
}

void Cloth::selectResponseColliders(std::span<const ColliderFrame> colliders) {
  // The response tests the end positions and the segments from the (carried) start points.
  Aabb end = Aabb::empty(), start = Aabb::empty();
  if (m_skipStages) {
    for (Index i = 0; i < vertexCount(); ++i) {
      if (m_pinnedMask[i]) continue;
      end.expand(m_positions[i]);
      start.expand(m_stepStartPositions[i]);
    }
  }
  selectNearColliders(colliders, end, &start);
}

StrainLimitReport Cloth::projectInContact(Real h, bool selfCollision, bool joint,
                                          const StrainLimitSettings& settings) {
  m_heldSeparations.clear();
  if (joint) {
    // Every self-contact any pass of this substep found, held at the separation that pass left
    // it at (a pair the last pass did not meet again may still be where an earlier one put it).
    if (selfCollision) {
      const std::vector<SeparationHold>& found = m_selfCollision->separationHolds();
      m_substepSelfHolds.insert(m_substepSelfHolds.end(), found.begin(), found.end());
    }
    m_heldSeparations.assign(m_substepSelfHolds.begin(), m_substepSelfHolds.end());
  } else if (selfCollision) {
    // The self-contacts of the last self-collision pass between features of very different
    // masses are held, one-sided: the limiter may move such a pair apart or slide it, not push
    // it closer than that pass left it (see kHeldContactMassRatio).
    for (const SeparationHold& hold : m_selfCollision->separationHolds()) {
      if (spansHeldMassRatio(hold, m_inverseMasses)) m_heldSeparations.push_back(hold);
    }
  }
  // Faces on a collider are held one-sided too (ColliderFaceContacts): the limiter slides them
  // round the body instead of pulling them back into it.
  const std::span<const SeparationHold> faceHolds = m_faceContacts.holds();
  m_heldSeparations.insert(m_heldSeparations.end(), faceHolds.begin(), faceHolds.end());
  if (joint) {
    // The collider contacts as one-sided constraints of the same iteration (ColliderProjection);
    // no vertex is held along a surface's normal, so the edges may also lift it off.
    // The vertices against every collider of the substep (a vertex may be pulled towards one
    // the skipped stages left out: the same bits with and without skipping), the faces against
    // those their last pass was given.
    m_colliderProjection.prepare(m_colliders,
                                 m_settings.faceContacts ? &m_faceContacts : nullptr,
                                 m_nearColliders, m_model->triangles(), m_inverseMasses,
                                 m_settings.material.thickness,
                                 std::max(m_settings.material.thickness,
                                          kProjectionMarginPerEdge * m_meanEdgeLength),
                                 m_positions);
    return m_strainLimiter->applyInContact(settings, m_inverseMasses, m_freeContactNormals, h,
                                           m_positions, m_velocities, *m_tasks,
                                           m_heldSeparations, &m_colliderProjection);
  }
  for (Index i = 0; i < vertexCount(); ++i) {
    m_heldInverseMasses[i] = m_contactHolds.fixed[i] ? 0 : m_inverseMasses[i];
  }
  return m_strainLimiter->applyInContact(settings, m_heldInverseMasses, m_contactHolds.normals, h,
                                         m_positions, m_velocities, *m_tasks, m_heldSeparations);
}

void Cloth::keepOutOfCollidersAfterProjection(std::span<ColliderFrame> colliders) {
  // Friction was taken in the first pass; this one only keeps vertices and faces out.
  m_projectedPositions = m_positions;
  selectResponseColliders(colliders);
  m_keepOutFromProjection = true;
  keepVerticesOutOfColliders();
  (void)resolveFaceContacts(/*frictionStep=*/0);
  m_keepOutFromProjection = false;
}

bool Cloth::jointProjection() const {
  // Where collider contacts and self-contacts meet, the sequential rounds fight (stress scene 7).
  // With collider contacts alone they converge, and hold a cloth resting on a body still: the
  // projection does not hold vertices along the surface and takes no friction, so a towel
  // resting on a rod by its faces crept along it (2.5 mm in 5 s, ColliderFaceContactsTest)
  // where the rounds leave it still (5 µm).
  return m_settings.jointContactProjection && m_colliderContacts > 0 && m_substepSelfContacts > 0;
}

Index Cloth::limitStrainInContact(Real h, std::span<ColliderFrame> colliders, bool selfCollision,
                                  Index edgesOverLimit, ClothFrameReport& report) {
  // The collision passes moved vertices after the limiter (out of a collider, apart from each
  // other, dragged by friction) and so stretched edges again. Without collider contacts (or with
  // the joint projection off): limit once more with the collider contacts held along their
  // normals and the self-contacts of very different masses held, then the collisions again;
  // repeat while they still stretch edges, a few times at most. With collider contacts: the
  // joint projection (ColliderProjection), then the collisions again, rounds until one finds
  // nothing to correct; if none does, a last projection has the last word (see
  // kJointProjectionRounds).
  WEFT_PROFILE_ZONE("strain limit in contact");
  const bool joint = jointProjection();
  m_substepSelfHolds.clear();
  const int rounds = joint ? kJointProjectionRounds : kContactLimitPasses;
  for (int pass = 0; pass < rounds; ++pass) {
    const StrainLimitReport limited =
        projectInContact(h, selfCollision, joint,
                         joint ? m_jointLimitSettings : m_strainLimitSettings);
    report.strainLimit.iterations += limited.iterations;
    edgesOverLimit = limited.edgesOverLimit;
    if (limited.iterations == 0) {
      // Nothing over the limit, nothing violated beyond the projection's tolerance: the
      // collisions stand. Its first projection may still have moved faces and vertices by less
      // than that tolerance; the collider passes put them exactly on their bounds.
      if (joint) keepOutOfCollidersAfterProjection(colliders);
      return edgesOverLimit;
    }
    if (joint) {
      keepOutOfCollidersAfterProjection(colliders);
    } else if (!colliders.empty()) {
      // Friction was taken in the first pass; this one only keeps vertices and faces out.
      selectResponseColliders(colliders);
      keepVerticesOutOfColliders();
      (void)resolveFaceContacts(/*frictionStep=*/0);
    }
    if (selfCollision) resolveSelfCollision(h, colliders, report);
  }
  if (joint) {
    // The rounds did not settle: the projection over every contact found has the last word, to
    // a tighter edge tolerance, so that the collider passes after it, which move vertices and
    // faces by at most the projection's tolerance (a hundredth of the thickness), keep the edges
    // within limit + tolerance.
    StrainLimitSettings last = m_jointLimitSettings;
    last.tolerance *= kLastProjectionTolerance;
    const StrainLimitReport limited = projectInContact(h, selfCollision, true, last);
    report.strainLimit.iterations += limited.iterations;
    edgesOverLimit = limited.edgesOverLimit;
    keepOutOfCollidersAfterProjection(colliders);
  }
  return edgesOverLimit;
}

HealthFailure Cloth::runSubsteps(Real t, Real frameDt, Index substeps,
                                 std::span<ColliderFrame> colliders, ClothFrameReport& report) {
  const Real h = frameDt / substeps;
  const RigidMotion* frameStart = m_frameStartMotions.data();
  // A pin yanked far in each substep makes every substep of the frame hard (tightPinTravel);
  // pins move on straight lines through the frame, so each substep has 1/substeps of the travel.
  const bool yanked =
      largestPinTravel() >= m_settings.solver.tightPinTravel * m_meanEdgeLength * Real(substeps);
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
    // The solve's contact impulses, for friction; none unless an implicit solve reports them.
    m_solveContactImpulses.assign(vertexCount(), Real(0));
    if (m_settings.solver.tightCgTolerance > 0) {
      // Contact-aware accuracy (SolverSettings::tightCgTolerance): jammed or yanked, solve tighter.
      if (m_jammed || yanked) {
        m_integrator->setSolveAccuracy(std::min(m_frameTolerance, m_settings.solver.tightCgTolerance),
                                       PcgStopping::RelativeResidual);
      } else {
        m_integrator->setSolveAccuracy(m_frameTolerance, m_settings.solver.cgStopping);
      }
    }
    // Self-contacts in the solve (SolverSettings::selfContactStiffness): the pairs in contact at
    // the step start, looked for when the last substep had self-contacts. The self-collision
    // pass after the solve reuses them (same start, ContactResolver::findProximityPairs).
    m_selfContactPairs.clear();
    if (m_selfContactStiffness > 0 && m_selfContactsLastStep) {
      m_selfCollision->findProximityPairs(m_stepStartPositions,
                                          kSelfContactSearch * m_settings.material.thickness,
                                          m_settings.material.friction, m_selfContactPairs);
    }
    const Index selfContactsBefore =
        report.selfCollision.proximityContacts + report.selfCollision.impacts;
    m_integrator->step(*this, m_positions, m_velocities, t + substep * h, h, substepReport);
    m_selfContactPairs.clear();
    m_contactCouplings.clear();
    Index edgesOverLimit = 0;
    if (m_strainLimiter) {
      // After the solve, before the collision passes; limitStrainInContact runs it again after
      // them, and they keep the last word.
      WEFT_PROFILE_ZONE("strain limit");
      const StrainLimitReport limited = m_strainLimiter->apply(
          m_strainLimitSettings, m_inverseMasses, h, m_positions, m_velocities, *m_tasks);
      report.strainLimit.iterations += limited.iterations;
      edgesOverLimit = limited.edgesOverLimit;
      m_contactHolds.clear();
    }
    Index contacts = 0;
    if (!colliders.empty()) {
      // Friction moves positions as well as velocities (positionStep h: a sticking contact does
      // not creep h² a_t a step) and is bounded by the impulse of the solve's contact constraint
      // (m_solveContactImpulses), not by the step's velocity change, which that constraint
      // cancels. ColliderResponse.h has the measurements.
      selectResponseColliders(colliders);
      const ColliderResponseReport contact = m_colliderResponse.resolve(
          m_nearColliders, m_stepStartPositions, m_stepStartVelocities,
          m_settings.material.thickness, m_pinnedMask, m_positions, m_velocities,
          m_strainLimiter ? &m_contactHolds : nullptr, /*friction=*/true, /*positionStep=*/h,
          m_solveContactImpulses);
      report.contacts = contact.contacts;
      const Index faceContacts = resolveFaceContacts(/*frictionStep=*/h);
      report.faceContacts += faceContacts;
      contacts = contact.contacts + faceContacts;
      m_colliderContacts = contacts;
    } else {
      m_faceContacts.clear();
      m_colliderContacts = 0;
    }
    const bool selfCollisionNeeded =
        m_selfCollision && !(m_skipStages && m_foldCulling->cannotTouchItself(
                                                 m_stepStartPositions, m_positions,
                                                 m_settings.material.thickness));
    if (m_selfCollision && !selfCollisionNeeded) ++m_stages.selfCollisionSkipped;
    Index selfContacts = 0;  // of this substep's first self pass: the jam measure
    if (m_selfCollision && m_strainLimiter) {
      // The joint projection holds every self-contact (limitStrainInContact); otherwise only
      // a cloth of very different masses holds any.
      m_selfCollision->setRecordSeparations(
          m_massesNeedSeparations || (m_settings.jointContactProjection && m_colliderContacts > 0));
    }
    if (selfCollisionNeeded) {
      const Index before = report.selfCollision.proximityContacts + report.selfCollision.impacts;
      resolveSelfCollision(h, colliders, report);
      selfContacts = report.selfCollision.proximityContacts + report.selfCollision.impacts - before;
    }
    m_substepSelfContacts = selfContacts;
    m_jammed = Real(selfContacts) >=
               m_settings.solver.tightSelfContactDensity * Real(vertexCount());
    if (m_strainLimiter && (contacts > 0 || selfCollisionNeeded)) {
      edgesOverLimit = limitStrainInContact(h, colliders, selfCollisionNeeded, edgesOverLimit, report);
    }
    report.strainLimit.edgesOverLimit += edgesOverLimit;
    m_selfContactsLastStep =
        report.selfCollision.proximityContacts + report.selfCollision.impacts > selfContactsBefore;
    report.integrator.linearSolves += substepReport.linearSolves;
    report.integrator.cgIterations += substepReport.cgIterations;
    report.integrator.cgResidual = substepReport.cgResidual;
    report.integrator.cgConverged = report.integrator.cgConverged && substepReport.cgConverged;
    report.integrator.potentialEnergy = substepReport.potentialEnergy;
    if (substep == 0) m_frameStartPotential = substepReport.potentialEnergy;
    report.integrator.assemblyMs += substepReport.assemblyMs;
    report.integrator.solveMs += substepReport.solveMs;
    report.integrator.solvedUnknowns = substepReport.solvedUnknowns;
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

HealthFailure Cloth::checkFrameHealth(Real startStrain, Real startKinetic, Real endStrain,
                                      Real endKinetic) const {
  if (endStrain > kDivergedStrain && endStrain > startStrain) return HealthFailure::Strain;
  // The energy the frame could give the cloth: what it had (kinetic, and elastic: the reported
  // potential minus gravity's part, −Σ m g·x), the whole cloth thrown at the fastest driver's
  // speed (pins, collider surfaces, wind), a free fall through its own size, and the work of
  // the per-vertex external forces.
  const std::vector<Real>& mass = masses();
  const Vec3& gravity = m_forces.settings().gravity;
  Real totalMass = 0, gravityPotential = 0;
  for (Index i = 0; i < vertexCount(); ++i) {
    totalMass += mass[i];
    gravityPotential -= mass[i] * gravity.dot(m_savedPositions[i]);
  }
  const Real elastic = std::max<Real>(0, m_frameStartPotential - gravityPotential);
  const Real size = m_model->characteristicLength();
  Real driverSpeed = std::max({kQuietSpeed, m_forces.settings().wind.norm(),
                               largestPinTravel() / m_frameLength});
  for (const RigidMotion& motion : m_frameStartMotions) {
    const Real reach = (motion.pose.position - m_savedPositions[0]).norm() + size;
    driverSpeed = std::max(driverSpeed, motion.linearVelocity.norm() +
                                            motion.angularVelocity.norm() * reach);
  }
  // Work of the caller's per-vertex forces: at most |F| times how far the vertex can go (its
  // size, its start speed over the frame, and the force's own push).
  Real externalWork = 0;
  const Vec3Array& external = m_forces.externalForces();
  for (std::size_t i = 0; i < external.size(); ++i) {
    const Real force = external[i].norm();
    if (force == 0) continue;
    const Real T = m_frameLength;
    externalWork += force * (size + m_savedVelocities[i].norm() * T + force * T * T / mass[i]);
  }
  const Real available = startKinetic + elastic + externalWork +
                         0.5 * totalMass * (driverSpeed * driverSpeed + 2 * gravity.norm() * size);
  if (endKinetic > kEnergyJumpFactor * available) return HealthFailure::EnergyJump;
  return HealthFailure::None;
}

void Cloth::save(SavedState& out) const {
  out.positions = m_positions;
  out.velocities = m_velocities;
  out.pinTargets = m_pinEnd;
  m_integrator->saveCarriedState(out.carried);
  out.sleeping = m_sleeping;
  out.wakeRequested = m_wakeRequested;
  out.quietFrames = m_quietFrames;
  out.sleepFingerprint = m_sleepFingerprint;
  out.potentialEnergy = m_lastPotential;
  out.jammed = m_jammed;
}

void Cloth::restore(const SavedState& in) {
  m_positions = in.positions;
  m_velocities = in.velocities;
  m_pinStart = m_pinEnd = in.pinTargets;
  m_integrator->restoreCarriedState(in.carried);
  m_normalsValid = false;
  m_sleeping = in.sleeping;
  m_wakeRequested = in.wakeRequested;
  m_quietFrames = in.quietFrames;
  m_sleepFingerprint = in.sleepFingerprint;
  m_lastPotential = in.potentialEnergy;
  m_jammed = in.jammed;
}

std::uint64_t Cloth::colliderFingerprint(std::span<const ColliderFrame> colliders, Real frameDt,
                                         bool* anyMoving) const {
  Aabb cloth = Aabb::empty();
  for (const Vec3& x : m_positions) cloth.expand(x);
  const Real margin = contactMargin(m_settings.material.thickness) + kWakeMargin;
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&hash](const void* data, std::size_t bytes) {
    const unsigned char* byte = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) hash = (hash ^ byte[k]) * 1099511628211ull;
  };
  *anyMoving = false;
  for (std::size_t k = 0; k < colliders.size(); ++k) {
    const RigidMotion& motion = colliders[k].start;
    const bool moving = !motion.linearVelocity.isZero() || !motion.angularVelocity.isZero();
    Real reach = margin;
    if (moving) {
      // Where the body can get within the frame: its travel, and for a spinning body the sweep
      // of its box about its origin.
      const Aabb box = bounds(*colliders[k].shape);
      const Real radius = std::max((box.min - motion.pose.position).norm(),
                                   (box.max - motion.pose.position).norm());
      reach += frameDt * (motion.linearVelocity.norm() + motion.angularVelocity.norm() * radius);
      if (!std::isfinite(reach)) reach = std::numeric_limits<Real>::max();
    }
    if (!colliderNear(*colliders[k].shape, cloth, reach)) continue;
    *anyMoving = *anyMoving || moving;
    mix(&k, sizeof k);
    mix(motion.pose.position.data(), sizeof(Real) * 3);
    mix(motion.pose.rotation.coeffs().data(), sizeof(Real) * 4);
  }
  return hash;
}

void Cloth::updateSleep(std::span<const ColliderFrame> colliders, Real frameDt, bool pinsMoved) {
  const SleepSettings& sleep = m_settings.sleep;
  if (!sleep.enabled) return;
  // Quiet: every free vertex slow, and its velocity barely changed over the frame — the
  // residual of M a = f, which is what keeps a cloth released from rest from sleeping.
  Real speed2 = 0, change2 = 0;
  for (Index i = 0; i < vertexCount(); ++i) {
    if (m_pinnedMask[i]) continue;
    speed2 = std::max(speed2, m_velocities[i].squaredNorm());
    change2 = std::max(change2, (m_velocities[i] - m_savedVelocities[i]).squaredNorm());
  }
  const bool quiet = !pinsMoved && speed2 < sleep.speed * sleep.speed &&
                     change2 < (sleep.acceleration * frameDt) * (sleep.acceleration * frameDt);
  m_quietFrames = quiet ? m_quietFrames + 1 : 0;
  if (m_quietFrames < sleep.frames) return;
  bool anyMoving = false;
  const std::uint64_t fingerprint = colliderFingerprint(colliders, frameDt, &anyMoving);
  if (anyMoving) return;  // a body moves near it: stay awake
  m_sleeping = true;
  m_sleepFingerprint = fingerprint;
  for (Vec3& v : m_velocities) v.setZero();
}

ClothFrameReport Cloth::stepFrame(Real t, Real frameDt, std::span<ColliderFrame> colliders,
                                  const StepPlan& plan) {
  ClothFrameReport report;
  m_stages = ClothStageCounters{};
  const bool pinsMoved = m_pinStart != m_pinEnd;
  if (m_sleeping) {
    bool anyMoving = false;
    const bool collidersChanged =
        colliderFingerprint(colliders, frameDt, &anyMoving) != m_sleepFingerprint || anyMoving;
    if (!m_wakeRequested && !pinsMoved && !collidersChanged) {
      // The frame starts and ends here: the cloth–cloth pass reads this as the frame's motion.
      m_savedPositions = m_positions;
      m_savedVelocities = m_velocities;
      report.sleeping = true;
      report.maxStrain = maxStrain();
      report.kineticEnergy = kineticEnergy();
      // Asleep means unchanged since the last stepped frame: its potential still holds (elastic
      // and gravity energy do not vanish because the cloth is not integrated).
      report.integrator.potentialEnergy = m_lastPotential;
      return report;
    }
    m_sleeping = false;
    m_quietFrames = 0;
    report.woke = true;
  }
  m_wakeRequested = false;

  // A teleport (SolverSettings::pinTeleportDistance, pinTeleportAngle): the cloth is carried with its pins' best-fit
  // rigid motion before the frame, so it arrives instead of being flung; the pins then move only
  // relative to it. The motion is rigid, so velocities turn with it (unchanged by a translation)
  // and so does the implicit solve's warm start (a Δv per vertex, in world axes); nothing else
  // the cloth keeps per vertex outlives a frame (the step-start copies and the collision caches
  // are taken from the carried positions). Before the rollback copy, so a failed frame stays
  // carried.
  if (const std::optional<RigidFit> carry = teleportMotion()) {
    for (Vec3& x : m_positions) x = carry->apply(x);
    for (Vec3& start : m_pinStart) start = carry->apply(start);
    if (!carry->translationOnly()) {
      for (Vec3& v : m_velocities) v = carry->rotation * v;
      m_integrator->rotateCarriedState(carry->rotation);
    }
    report.teleported = true;
  }

  // The carry is applied: the pins' frame-start targets above are already carried, so their
  // travel is measured as it is (fitting them again would look for a second teleport).
  bool predictedUnstable = false;
  Index substeps = plannedSubsteps(frameDt, &predictedUnstable, std::nullopt);
  if (plan.substeps > 0) {
    substeps = plan.substeps;
    predictedUnstable = m_settings.solver.integrator != IntegratorKind::ImplicitEuler &&
                        frameDt / substeps > m_stableStep;
  }
  if (predictedUnstable) report.status |= StepStatus::Unstable;
  m_frameTolerance = plan.cgTolerance > 0 ? plan.cgTolerance : m_settings.solver.cgTolerance;
  m_integrator->setSolveLimits(
      m_frameTolerance,
      plan.cgMaxIterations > 0 ? plan.cgMaxIterations : m_settings.solver.cgMaxIterations);
  m_frameStartJammed = m_jammed;
  m_nearColliders.reserve(colliders.size());  // allocates only when colliders are added

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
    report.strainLimit = StrainLimitReport{};
    HealthFailure failure = runSubsteps(t, frameDt, substeps, colliders, report);
    if (failure == HealthFailure::None) {
      WEFT_PROFILE_ZONE("health");
      // Kept for the report too: World's statistics read them instead of measuring again.
      report.maxStrain = maxStrain();
      report.kineticEnergy = kineticEnergy();
      failure = checkFrameHealth(startStrain, startKinetic, report.maxStrain, report.kineticEnergy);
    }
    if (failure == HealthFailure::None) break;
    report.healthFailure = failure;
    m_positions = m_savedPositions;
    m_velocities = m_savedVelocities;
    report.maxStrain = startStrain;  // back where the frame started
    report.kineticEnergy = startKinetic;
    m_integrator->reset();  // the failed attempt's Δv is no warm start
    m_jammed = m_frameStartJammed;
    report.status |= StepStatus::Unstable;
    if (attempt == kMaxRetries) {
      report.status |= StepStatus::RolledBack;
      break;
    }
    report.status |= StepStatus::RetriedWithSmallerStep;
    substeps *= 2;
  }
  m_colliders = {};
  // A rolled-back frame ends where it started: the potential of its first substep's start.
  m_lastPotential = hasFlag(report.status, StepStatus::RolledBack) ? m_frameStartPotential
                                                                   : report.integrator.potentialEnergy;
  if (!report.integrator.cgConverged) report.status |= StepStatus::SolverNotConverged;
  m_pinStart = m_pinEnd;  // next frame starts where this one ended
  m_normalsValid = false;
  if (hasFlag(report.status, StepStatus::Unstable)) {
    m_quietFrames = 0;
  } else {
    updateSleep(colliders, frameDt, pinsMoved);
  }
  report.stages = m_stages;
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
