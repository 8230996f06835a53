#include <weft/engine/World.h>

#include "Cloth.h"
#include "FrameCostModel.h"
#include "SubstepPipeline.h"

#include <weft/engine/InputFile.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>
#include <sstream>

namespace weft {

std::string describe(StepStatus status) {
  if (status == StepStatus::Ok) return "ok";
  std::string text;
  auto add = [&](StepStatus flag, const char* name) {
    if (!hasFlag(status, flag)) return;
    if (!text.empty()) text += '|';
    text += name;
  };
  add(StepStatus::Unstable, "unstable");
  add(StepStatus::SolverNotConverged, "solver-not-converged");
  add(StepStatus::RolledBack, "rolled-back");
  add(StepStatus::InvalidInput, "invalid-input");
  add(StepStatus::RetriedWithSmallerStep, "retried-with-smaller-step");
  add(StepStatus::BudgetMissed, "budget-missed");
  add(StepStatus::StrainLimitExceeded, "strain-limit-exceeded");
  add(StepStatus::Squeezed, "squeezed");
  add(StepStatus::ContactsFrozen, "contacts-frozen");
  add(StepStatus::ContactsUnresolved, "contacts-unresolved");
  return text;
}

/// A pinned vertex whose target follows a collider.
struct ColliderAttachment {
  Index pinSlot = 0;     // index into ClothSettings::pinnedVertices
  ColliderId collider;
  Vec3 localOffset = Vec3::Zero();  // m, the vertex in the collider's body frame
};

const char* describe(HealthFailure failure) {
  switch (failure) {
    case HealthFailure::None: return "none";
    case HealthFailure::NonFinite: return "non-finite";
    case HealthFailure::Speed: return "speed";
    case HealthFailure::Strain: return "strain";
    case HealthFailure::EnergyJump: return "energy-jump";
    case HealthFailure::OutOfRange: return "out-of-range";
  }
  return "unknown";
}

struct World::ClothSlot {
  std::unique_ptr<Cloth> cloth;  // null when free
  std::uint32_t generation = 1;
  std::vector<ColliderAttachment> attachments;  // sorted by pinSlot
};

struct World::ColliderSlot {
  std::optional<Shape> shape;  // empty when free
  ColliderSettings settings;
  std::uint32_t generation = 1;
};

struct WorldState::Data {
  std::uint64_t world = 0;  // World::m_identity of the world that saved it (0: none)
  Real time = 0;
  std::uint64_t frame = 0;
  std::vector<std::pair<ClothId, Cloth::SavedState>> cloths;
  std::vector<std::pair<ColliderId, RigidMotion>> colliders;
};

WorldState::WorldState() : m_data(std::make_unique<Data>()) {}
WorldState::~WorldState() = default;
// A moved-from state holds no data; copying it gives an empty state, which restoreState refuses.
WorldState::WorldState(const WorldState& other)
    : m_data(other.m_data ? std::make_unique<Data>(*other.m_data) : std::make_unique<Data>()) {}
WorldState& WorldState::operator=(const WorldState& other) {
  if (this != &other) m_data = other.m_data ? std::make_unique<Data>(*other.m_data) : std::make_unique<Data>();
  return *this;
}
WorldState::WorldState(WorldState&&) noexcept = default;
WorldState& WorldState::operator=(WorldState&&) noexcept = default;

namespace {
// Identities of worlds, for WorldState: never 0, never reused within a process.
std::atomic<std::uint64_t> g_nextWorldIdentity{1};
}  // namespace

namespace {
std::string formatVector(const Vec3& v) {
  std::ostringstream text;
  text << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return text.str();
}

// Empty when `gravity` is finite and within kMaxGravity; else what is wrong, for `field`.
std::string gravityProblem(const Vec3& gravity, const std::string& field) {
  if (!gravity.allFinite()) {
    return field + " contains NaN or infinity (gravity or wind must be finite); give m/s²";
  }
  if (gravity.norm() <= kMaxGravity) return {};
  std::ostringstream text;
  text << field << " " << formatVector(gravity) << " m/s² is stronger than " << kMaxGravity
       << " m/s² (kMaxGravity: a second of fall would reach " << kMaxSpeed
       << " m/s, which the engine treats as divergence); give a gravity within it";
  return text.str();
}

// Empty when `wind` is finite and within kMaxSpeed; else what is wrong, for `field`.
std::string windProblem(const Vec3& wind, const std::string& field) {
  if (!wind.allFinite()) {
    return field + " contains NaN or infinity (gravity or wind must be finite); give m/s";
  }
  if (wind.norm() <= kMaxSpeed) return {};
  std::ostringstream text;
  text << field << " " << formatVector(wind) << " m/s is faster than " << kMaxSpeed
       << " m/s (kMaxSpeed, which the engine treats as divergence); give a wind within it";
  return text.str();
}

// Why `settings` cannot make a world, naming the field and the fix; empty when they can.
std::string settingsProblem(const WorldSettings& settings) {
  if (std::string problem = gravityProblem(settings.gravity, "world settings: WorldSettings::gravity");
      !problem.empty()) {
    return problem;
  }
  if (std::string problem = windProblem(settings.wind, "world settings: WorldSettings::wind");
      !problem.empty()) {
    return problem;
  }
  if (!settings.taskSystem && !validate(TaskSystemSettings{settings.threadCount}).empty()) {
    return "world settings: WorldSettings::threadCount = " + std::to_string(settings.threadCount) +
           " is out of range: give 0 (the machine's cores), 1 (serial) or up to " +
           std::to_string(TaskSystemSettings::kMaxThreadCount) + " threads";
  }
  return {};
}

// The first vector of `values` longer than `limit`, as an error "<name(k)> is (x, y, z) <unit>,
// <comparison> <limit> <unit> (<why>)"; non-finite ones are the callee's check.
template <typename Name>
Status checkLength(std::span<const Vec3> values, Real limit, Name name, const char* comparison,
                   const char* unit, const char* why) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!values[k].allFinite() || values[k].norm() <= limit) continue;
    std::ostringstream text;
    text << name(k) << " is " << formatVector(values[k]) << " " << unit << ", " << comparison << " "
         << limit << " " << unit << " (" << why << "); give a value within it";
    return Error{text.str()};
  }
  return Status::success();
}

// The first point of `points` with a coordinate beyond kMaxCoordinate, as an error of
// `operation` that calls point k "<what> k"; success when there is none.
Status checkReach(std::span<const Vec3> points, const char* operation, const char* what) {
  for (std::size_t k = 0; k < points.size(); ++k) {
    // Non-finite values are the cloth's own check (with its message).
    if (!points[k].allFinite() || points[k].cwiseAbs().maxCoeff() <= kMaxCoordinate) continue;
    std::ostringstream text;
    text << operation << ": " << what << " " << k << " is at (" << points[k].x() << ", "
         << points[k].y() << ", " << points[k].z() << ") m, beyond the " << kMaxCoordinate
         << " m a coordinate may have (kMaxCoordinate, where doubles still resolve 0.1 nm); keep "
            "the simulation near the origin (move the origin with the player)";
    return Error{text.str()};
  }
  return Status::success();
}
}  // namespace

Result<World> World::create(const WorldSettings& settings) {
  if (std::string problem = settingsProblem(settings); !problem.empty()) return Error{problem};
  return World(settings);
}

World::World(const WorldSettings& settings)
    : m_settings(settings),
      m_costModel(std::make_unique<FrameCostModel>()),
      m_identity(g_nextWorldIdentity.fetch_add(1)),
      m_settingsError(settingsProblem(settings)) {
  if (settings.taskSystem) {
    m_tasks = settings.taskSystem;
  } else {
    // An invalid count gives the serial TaskSystem; createCloth() reports the mistake.
    m_ownedTasks = std::make_unique<TaskSystem>(TaskSystemSettings{settings.threadCount});
    m_tasks = m_ownedTasks.get();
  }
  m_pipeline = std::make_unique<SubstepPipeline>(m_tasks, settings.skipUnneededStages);
}

std::uint64_t World::estimatedClothBytes(std::uint64_t vertices, std::uint64_t triangles) {
  // Measured peaks (bench/results/memory-footprint.md): 7.0-8.2 kB a vertex for createCloth()
  // and the first frames of a hanging cloth of 2 triangles a vertex; a third more for buffers
  // that grow in steps and for contacts.
  constexpr std::uint64_t kBytesPerVertex = 6144, kBytesPerTriangle = 2560;
  return kBytesPerVertex * vertices + kBytesPerTriangle * triangles;
}

int World::threadCount() const { return m_tasks->threadCount(); }
World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

const World::ClothSlot* World::find(ClothId id) const {
  if (id.index == 0 || id.index > m_slots.size()) return nullptr;
  const ClothSlot* slot = m_slots[id.index - 1].get();
  return (slot->cloth && slot->generation == id.generation) ? slot : nullptr;
}

World::ClothSlot* World::find(ClothId id) {
  return const_cast<ClothSlot*>(static_cast<const World*>(this)->find(id));
}

const World::ColliderSlot* World::find(ColliderId id) const {
  if (id.index == 0 || id.index > m_colliderSlots.size()) return nullptr;
  const ColliderSlot* slot = m_colliderSlots[id.index - 1].get();
  return (slot->shape && slot->generation == id.generation) ? slot : nullptr;
}

World::ColliderSlot* World::find(ColliderId id) {
  return const_cast<ColliderSlot*>(static_cast<const World*>(this)->find(id));
}

namespace {
Error staleHandle(const char* operation, ClothId id) {
  return Error{std::string(operation) + ": cloth handle {" + std::to_string(id.index) + ", " +
               std::to_string(id.generation) +
               "} is null or refers to a destroyed cloth; use the handle createCloth() returned"};
}
}  // namespace

Result<ClothId> World::createCloth(std::shared_ptr<const ClothModel> model,
                                   const ClothSettings& settings) {
  if (!m_settingsError.empty()) return Error{m_settingsError};
  if (model) {
    if (Status memory = checkMemory(estimatedClothBytes(model->vertexCount(), model->triangleCount()),
                                    "a cloth of " + std::to_string(model->vertexCount()) + " vertices",
                                    "use a coarser model");
        !memory.ok()) {
      return memory.error();
    }
  }
  Result<std::unique_ptr<Cloth>> cloth =
      Cloth::create(std::move(model), settings, m_settings, m_tasks);
  if (!cloth.ok()) return cloth.error();
  m_pipeline->clothsChanged();
  for (std::size_t k = 0; k < m_slots.size(); ++k) {
    if (!m_slots[k]->cloth) {
      m_slots[k]->cloth = std::move(cloth.value());
      return ClothId{std::uint32_t(k + 1), m_slots[k]->generation};
    }
  }
  m_slots.push_back(std::make_unique<ClothSlot>());
  m_slots.back()->cloth = std::move(cloth.value());
  return ClothId{std::uint32_t(m_slots.size()), m_slots.back()->generation};
}

Result<ColliderId> World::addCollider(const Shape& shape, const ColliderSettings& settings) {
  if (!(std::isfinite(settings.friction) && settings.friction >= 0)) {
    return Error{"addCollider: friction = " + std::to_string(settings.friction) +
                 " must be finite and at least 0"};
  }
  const Vec3 velocity = motion(shape).linearVelocity;
  if (Status speed = checkLength(
          std::span<const Vec3>(&velocity, 1), kMaxSpeed,
          [](std::size_t) { return std::string("addCollider: the collider's linear velocity"); },
          "faster than", "m/s", "kMaxSpeed, which the engine treats as divergence");
      !speed.ok()) {
    return speed.error();
  }
  for (std::size_t k = 0; k < m_colliderSlots.size(); ++k) {
    if (!m_colliderSlots[k]->shape) {
      m_colliderSlots[k]->shape = shape;
      m_colliderSlots[k]->settings = settings;
      return ColliderId{std::uint32_t(k + 1), m_colliderSlots[k]->generation};
    }
  }
  m_colliderSlots.push_back(std::make_unique<ColliderSlot>());
  m_colliderSlots.back()->shape = shape;
  m_colliderSlots.back()->settings = settings;
  return ColliderId{std::uint32_t(m_colliderSlots.size()), m_colliderSlots.back()->generation};
}

namespace {
Error staleCollider(const char* operation, ColliderId id) {
  return Error{std::string(operation) + ": collider handle {" + std::to_string(id.index) + ", " +
               std::to_string(id.generation) +
               "} is null or refers to a destroyed collider; use the handle addCollider() returned"};
}
}  // namespace

Status World::destroyCollider(ColliderId id) {
  ColliderSlot* slot = find(id);
  if (!slot) return staleCollider("destroyCollider", id);
  for (const std::unique_ptr<ClothSlot>& cloth : m_slots) {
    std::erase_if(cloth->attachments,
                  [&](const ColliderAttachment& attachment) { return attachment.collider == id; });
  }
  slot->shape.reset();
  ++slot->generation;
  return Status::success();
}

Status World::setColliderMotion(ColliderId id, const RigidMotion& motion) {
  ColliderSlot* slot = find(id);
  if (!slot) return staleCollider("setColliderMotion", id);
  if (Status speed = checkLength(
          std::span<const Vec3>(&motion.linearVelocity, 1), kMaxSpeed,
          [](std::size_t) { return std::string("setColliderMotion: the linear velocity"); },
          "faster than", "m/s", "kMaxSpeed, which the engine treats as divergence");
      !speed.ok()) {
    return speed;
  }
  return setMotion(*slot->shape, motion);
}

Result<const Shape*> World::collider(ColliderId id) const {
  const ColliderSlot* slot = find(id);
  if (!slot) return staleCollider("collider", id);
  return &*slot->shape;
}

Status World::destroyCloth(ClothId id) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("destroyCloth", id);
  slot->cloth.reset();
  m_pipeline->clothsChanged();
  slot->attachments.clear();
  ++slot->generation;  // every copy of the old handle is now stale
  return Status::success();
}

Status World::setPinTargets(ClothId id, std::span<const Vec3> targets) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("setPinTargets", id);
  // Counts are the cloth's check (with its message); values are looked at once they match.
  if (targets.size() == slot->cloth->pinTargets().size()) {
    if (Status reach = checkReach(targets, "setPinTargets", "target"); !reach.ok()) return reach;
  }
  if (Status torn = slot->cloth->checkPinnedEdges(targets); !torn.ok()) return torn;
  return slot->cloth->setPinTargets(targets);
}

namespace {
// Where each vertex sits in ClothSettings::pinnedVertices, or an error naming the first vertex
// that is not pinned.
Result<std::vector<Index>> pinSlotsOf(const char* operation, const ClothSettings& settings,
                                      Index vertexCount, std::span<const Index> vertices) {
  std::vector<Index> slots;
  slots.reserve(vertices.size());
  for (Index vertex : vertices) {
    if (vertex >= vertexCount) {
      return Error{std::string(operation) + ": vertex " + std::to_string(vertex) +
                   " is out of range; the cloth has " + std::to_string(vertexCount) + " vertices"};
    }
    const auto& pins = settings.pinnedVertices;
    const auto found = std::find(pins.begin(), pins.end(), vertex);
    if (found == pins.end()) {
      return Error{std::string(operation) + ": vertex " + std::to_string(vertex) +
                   " is not pinned; list it in ClothSettings::pinnedVertices to attach it"};
    }
    slots.push_back(Index(found - pins.begin()));
  }
  return slots;
}
}  // namespace

Status World::attachToCollider(ClothId id, std::span<const Index> vertices,
                               ColliderId colliderId) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("attachToCollider", id);
  const ColliderSlot* collider = find(colliderId);
  if (!collider) return staleCollider("attachToCollider", colliderId);
  Result<std::vector<Index>> slots = pinSlotsOf("attachToCollider", slot->cloth->settings(),
                                                slot->cloth->vertexCount(), vertices);
  if (!slots.ok()) return slots.error();
  const Pose& pose = motion(*collider->shape).pose;
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const Index pinSlot = slots.value()[k];
    std::erase_if(slot->attachments,
                  [&](const ColliderAttachment& a) { return a.pinSlot == pinSlot; });
    // The offset from where the pin is headed, so a pin mid-way along a scripted path is caught
    // where the caller last put it.
    const Vec3 target = slot->cloth->pinTargets()[pinSlot];
    slot->attachments.push_back(ColliderAttachment{pinSlot, colliderId, pose.toLocal(target)});
  }
  std::sort(slot->attachments.begin(), slot->attachments.end(),
            [](const ColliderAttachment& a, const ColliderAttachment& b) {
              return a.pinSlot < b.pinSlot;
            });
  return Status::success();
}

Status World::detachFromCollider(ClothId id, std::span<const Index> vertices) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("detachFromCollider", id);
  Result<std::vector<Index>> slots = pinSlotsOf("detachFromCollider", slot->cloth->settings(),
                                                slot->cloth->vertexCount(), vertices);
  if (!slots.ok()) return slots.error();
  for (Index pinSlot : slots.value()) {
    std::erase_if(slot->attachments,
                  [&](const ColliderAttachment& a) { return a.pinSlot == pinSlot; });
  }
  return Status::success();
}

Result<Index> World::attachedVertexCount(ClothId id) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("attachedVertexCount", id);
  return Index(slot->attachments.size());
}

Status World::setExternalForces(ClothId id, std::span<const Vec3> forces) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("setExternalForces", id);
  if (!forces.empty() && forces.size() != slot->cloth->vertexCount()) {
    return slot->cloth->setExternalForces(forces);  // refuses the count, naming it
  }
  if (Status size = checkLength(
          forces, kMaxMaterialValue,
          [](std::size_t k) { return "setExternalForces: the force on vertex " + std::to_string(k); },
          "larger than", "N", "kMaxMaterialValue, beyond which the solver's arithmetic overflows");
      !size.ok()) {
    return size;
  }
  return slot->cloth->setExternalForces(forces);
}

Status World::setWind(const Vec3& wind) {
  if (!wind.allFinite()) {
    return Error{"setWind: the wind velocity is NaN or infinite; give it in m/s"};
  }
  if (std::string problem = windProblem(wind, "setWind: the wind"); !problem.empty()) {
    return Error{problem};
  }
  m_settings.wind = wind;
  m_settingsError = settingsProblem(m_settings);
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (slot->cloth) slot->cloth->setExternalFields(m_settings.gravity, m_settings.wind);
  }
  return Status::success();
}

Status World::setState(ClothId id, std::span<const Vec3> positions,
                       std::span<const Vec3> velocities) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("setState", id);
  const std::size_t n = slot->cloth->vertexCount();
  if (positions.size() != n || velocities.size() != n) return slot->cloth->setState(positions, velocities);
  if (Status reach = checkReach(positions, "setState", "vertex"); !reach.ok()) return reach;
  if (Status speed = checkLength(
          velocities, kMaxSpeed,
          [](std::size_t k) { return "setState: the velocity of vertex " + std::to_string(k); },
          "faster than", "m/s", "kMaxSpeed, which the engine treats as divergence");
      !speed.ok()) {
    return speed;
  }
  return slot->cloth->setState(positions, velocities);
}

Result<std::vector<Vec3>> World::pinTargets(ClothId id) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("pinTargets", id);
  return std::vector<Vec3>(slot->cloth->pinTargets().begin(), slot->cloth->pinTargets().end());
}

void World::updateAttachedPins(Real frameDt) {
  // Attached pins end the frame where their collider's pose, advanced by its velocities, puts
  // them; across the frame they move linearly like every pin (the chord of a turning collider's
  // arc, which one frame keeps short).
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (!slot->cloth || slot->attachments.empty()) continue;
    const Vec3Array& targets = slot->cloth->pinTargets();
    m_attachedTargets.assign(targets.begin(), targets.end());
    for (const ColliderAttachment& attachment : slot->attachments) {
      const ColliderSlot* collider = find(attachment.collider);
      const Pose end = advanceMotion(motion(*collider->shape), frameDt).pose;
      m_attachedTargets[attachment.pinSlot] = end.toWorld(attachment.localOffset);
    }
    (void)slot->cloth->setPinTargets(m_attachedTargets);
  }
}

Status World::setGravity(const Vec3& gravity) {
  if (!gravity.allFinite()) return Error{"setGravity: gravity contains NaN or infinity"};
  if (std::string problem = gravityProblem(gravity, "setGravity: gravity"); !problem.empty()) {
    return Error{problem};
  }
  m_settings.gravity = gravity;
  m_settingsError = settingsProblem(m_settings);
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (slot->cloth) slot->cloth->setExternalFields(m_settings.gravity, m_settings.wind);
  }
  return Status::success();
}

Status World::wake(ClothId id) {
  ClothSlot* slot = find(id);
  if (!slot) return staleHandle("wake", id);
  slot->cloth->wake();
  return Status::success();
}

Result<bool> World::isSleeping(ClothId id) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("isSleeping", id);
  return slot->cloth->sleeping();
}

namespace {
// Weight of the newest frame in the cost model when steps come without a budget.
constexpr Real kDefaultCostSmoothing = 0.3;
}  // namespace

StepStatus World::step(Real frameDt) {
  return stepWithPlan(frameDt, StepPlan{}, 0, kDefaultCostSmoothing);
}

StepStatus World::step(Real frameDt, const StepPlan& plan) {
  Index mostSubsteps = 0;  // a plan may not ask for more substeps than any cloth allows itself
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (slot->cloth) mostSubsteps = std::max(mostSubsteps, slot->cloth->settings().solver.maxSubsteps);
  }
  if (!(std::isfinite(plan.cgTolerance) && plan.cgTolerance >= 0 && plan.cgTolerance < 1) ||
      plan.cgMaxIterations < 0 || plan.substeps > mostSubsteps) {
    m_stats.status = StepStatus::InvalidInput;
    return m_stats.status;
  }
  return stepWithPlan(frameDt, plan, 0, kDefaultCostSmoothing);
}

StepStatus World::step(Real frameDt, const StepBudget& budget) {
  const bool valid = std::isfinite(budget.milliseconds) && budget.milliseconds >= 0 &&
                     std::isfinite(budget.loosestCgTolerance) && budget.loosestCgTolerance > 0 &&
                     budget.loosestCgTolerance < 1 && budget.fewestCgIterations >= 1 &&
                     budget.fewestSubsteps >= 1 && budget.costSmoothing > 0 &&
                     budget.costSmoothing <= 1 && budget.headroom > 0 && budget.headroom <= 1 &&
                     budget.strainGuard > 0;
  if (!valid) {
    m_stats.status = StepStatus::InvalidInput;
    return m_stats.status;
  }
  if (budget.milliseconds == 0) return step(frameDt);
  if (!(std::isfinite(frameDt) && frameDt > 0)) return stepWithPlan(frameDt, {}, 0, 1);
  // What the cloths would run on their own: the planner relaxes from there.
  PlanDefaults defaults;
  bool first = true;
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (!slot->cloth || slot->cloth->sleeping()) continue;
    const Cloth& cloth = *slot->cloth;
    const SolverSettings& solver = cloth.settings().solver;
    const Index substeps = cloth.plannedSubsteps(frameDt);
    defaults.substeps = first ? substeps : std::max(defaults.substeps, substeps);
    defaults.cgTolerance = first ? solver.cgTolerance : std::min(defaults.cgTolerance, solver.cgTolerance);
    defaults.cgMaxIterations =
        first ? solver.cgMaxIterations : std::max(defaults.cgMaxIterations, solver.cgMaxIterations);
    defaults.allImplicit = defaults.allImplicit && solver.integrator == IntegratorKind::ImplicitEuler;
    first = false;
  }
  // The strain guard: after a frame that stretched the cloth beyond it, run the full settings.
  const bool guarded = !(m_stats.maxStrain <= budget.strainGuard);
  const StepPlan plan = (first || guarded) ? StepPlan{} : m_costModel->plan(budget, defaults);
  const StepStatus status =
      stepWithPlan(frameDt, plan, budget.milliseconds, budget.costSmoothing, defaults.cgTolerance);
  return status;
}

StepStatus World::stepWithPlan(Real frameDt, const StepPlan& plan, Real budgetMs,
                               Real costSmoothing, Real defaultTolerance) {
  const auto start = std::chrono::steady_clock::now();
  Profiler::instance().beginFrame(m_stats.frame + 1);
  WEFT_PROFILE_ZONE("step");
  // The world's clock must stay finite too (two frames of 1e308 s would not).
  if (!(std::isfinite(frameDt) && frameDt > 0 && std::isfinite(m_time + frameDt))) {
    m_stats.status = StepStatus::InvalidInput;
    return m_stats.status;
  }
  StepStats stats;
  stats.frame = m_stats.frame + 1;
  stats.plan = plan;
  stats.budgetMs = budgetMs;
  updateAttachedPins(frameDt);
  // The colliders at the frame start; the pipeline poses its own copies per substep, and they
  // end the frame advanced by their velocities.
  m_colliderSources.clear();
  for (const std::unique_ptr<ColliderSlot>& collider : m_colliderSlots) {
    if (collider->shape) m_colliderSources.push_back({&*collider->shape, collider->settings.friction});
  }
  m_steppedCloths.clear();
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (slot->cloth) m_steppedCloths.push_back(slot->cloth.get());
  }
  m_pipeline->stepFrame(m_steppedCloths, m_colliderSources, m_time, frameDt, plan, stats);
  for (const std::unique_ptr<ColliderSlot>& collider : m_colliderSlots) {
    if (collider->shape) {
      (void)setMotion(*collider->shape, advanceMotion(motion(*collider->shape), frameDt));
    }
  }
  const Index totalSubsteps = stats.substeps * (Index(m_steppedCloths.size()) - stats.sleepingCloths);
  m_time += frameDt;
  stats.simulatedTime = m_time;
  stats.stepMs =
      std::chrono::duration<Real, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (budgetMs > 0 && stats.stepMs > budgetMs) stats.status |= StepStatus::BudgetMissed;
  m_costModel->record(stats, totalSubsteps,
                      plan.cgTolerance > 0 ? plan.cgTolerance : defaultTolerance, costSmoothing);
  m_stats = stats;
  return stats.status;
}

Result<ClothRenderView> World::renderView(ClothId id) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("renderView", id);
  Cloth& cloth = *slot->cloth;
  return ClothRenderView{cloth.positions(), cloth.normals(), cloth.model().indices()};
}

Result<std::span<const Vec3>> World::positions(ClothId id) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("positions", id);
  return std::span<const Vec3>(slot->cloth->positions());
}

Result<std::span<const Vec3>> World::velocities(ClothId id) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("velocities", id);
  return std::span<const Vec3>(slot->cloth->velocities());
}

Result<Index> World::plannedSubsteps(ClothId id, Real frameDt) const {
  const ClothSlot* slot = find(id);
  if (!slot) return staleHandle("plannedSubsteps", id);
  if (!(std::isfinite(frameDt) && frameDt > 0)) {
    return Error{"plannedSubsteps: frameDt must be finite and greater than 0 s"};
  }
  return slot->cloth->plannedSubsteps(frameDt);
}

WorldState World::saveState() const {
  WorldState state;
  state.m_data->world = m_identity;
  state.m_data->time = m_time;
  state.m_data->frame = m_stats.frame;
  for (std::size_t k = 0; k < m_slots.size(); ++k) {
    if (!m_slots[k]->cloth) continue;
    state.m_data->cloths.emplace_back(ClothId{std::uint32_t(k + 1), m_slots[k]->generation},
                                      Cloth::SavedState{});
    m_slots[k]->cloth->save(state.m_data->cloths.back().second);
  }
  for (std::size_t k = 0; k < m_colliderSlots.size(); ++k) {
    if (!m_colliderSlots[k]->shape) continue;
    state.m_data->colliders.emplace_back(
        ColliderId{std::uint32_t(k + 1), m_colliderSlots[k]->generation},
        motion(*m_colliderSlots[k]->shape));
  }
  return state;
}

Status World::restoreState(const WorldState& state) {
  // Check everything first, so a failed restore changes nothing.
  if (!state.m_data || state.m_data->world != m_identity) {
    return Error{!state.m_data || state.m_data->world == 0
                     ? "restoreState: the state is empty; take one with World::saveState()"
                     : "restoreState: the state was saved by another World; restore it into the "
                       "world whose saveState() made it"};
  }
  for (const auto& [id, saved] : state.m_data->cloths) {
    const ClothSlot* slot = find(id);
    if (!slot) return staleHandle("restoreState: the saved cloth", id);
    if (saved.positions.size() != slot->cloth->vertexCount()) {
      return Error{"restoreState: cloth {" + std::to_string(id.index) + ", " +
                   std::to_string(id.generation) + "} no longer has the saved vertex count"};
    }
  }
  for (const auto& [id, saved] : state.m_data->colliders) {
    if (!find(id)) return staleCollider("restoreState: the saved collider", id);
  }
  for (const auto& [id, saved] : state.m_data->cloths) find(id)->cloth->restore(saved);
  for (const auto& [id, saved] : state.m_data->colliders) (void)setMotion(*find(id)->shape, saved);
  m_time = state.m_data->time;
  m_stats = StepStats{};
  m_stats.frame = state.m_data->frame;
  m_stats.simulatedTime = m_time;
  return Status::success();
}

std::uint64_t World::stateHash() const {
  // FNV-1a over the raw bytes: any bit that differs changes the hash.
  std::uint64_t hash = 1469598103934665603ull;
  auto mix = [&hash](const Vec3Array& values) {
    for (const Vec3& value : values) {
      unsigned char bytes[sizeof(Real) * 3];
      std::memcpy(bytes, value.data(), sizeof(bytes));
      for (unsigned char byte : bytes) hash = (hash ^ byte) * 1099511628211ull;
    }
  };
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) {
    if (!slot->cloth) continue;
    mix(slot->cloth->positions());
    mix(slot->cloth->velocities());
  }
  return hash;
}

Index World::clothCount() const {
  Index count = 0;
  for (const std::unique_ptr<ClothSlot>& slot : m_slots) count += slot->cloth ? 1 : 0;
  return count;
}

}  // namespace weft
