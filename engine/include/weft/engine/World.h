// World: owns cloths and steps them.
//
// Callers hold small handles (ClothId) with a generation counter: zero is null, and a handle to
// a destroyed cloth is refused with an error instead of touching reused memory (Box2D b2BodyId).
// Cloths are built from a shared, immutable ClothModel plus per-instance settings.
//
// One frame: World::step(frameDt) splits the frame into substeps per cloth (SolverSettings),
// moves pins linearly from their previous targets to the targets set for this frame, integrates,
// checks health (finite state, divergence) and fills StepStats. step() never throws; a frame that
// produces non-finite state is undone and reported (StepStatus::RolledBack).
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/collision/Shape.h>
#include <weft/engine/ClothModel.h>
#include <weft/engine/Material.h>
#include <weft/engine/RenderView.h>
#include <weft/engine/SolverSettings.h>
#include <weft/engine/StepBudget.h>
#include <weft/engine/StepStats.h>
#include <weft/threading/TaskSystem.h>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace weft {

struct ColliderSource;  // internal: a collider as a frame sees it
class Cloth;           // internal: one cloth's state, forces and integrator
class FrameCostModel;  // internal: the budget planner
class SubstepPipeline;  // internal: the frame's substeps

/// Handle to a cloth in a World. Zero-initialised = null.
struct ClothId {
  std::uint32_t index = 0;       ///< slot + 1 (0 = null)
  std::uint32_t generation = 0;  ///< must match the slot's generation
  /// True for the zero-initialised (null) handle.
  bool isNull() const { return index == 0; }
  /// Same slot and generation.
  friend bool operator==(const ClothId&, const ClothId&) = default;
};

/// Handle to a collider in a World. Zero-initialised = null.
struct ColliderId {
  std::uint32_t index = 0;       ///< slot + 1 (0 = null)
  std::uint32_t generation = 0;  ///< must match the slot's generation
  /// True for the zero-initialised (null) handle.
  bool isNull() const { return index == 0; }
  /// Same slot and generation.
  friend bool operator==(const ColliderId&, const ColliderId&) = default;
};

/// Per-instance settings of a collider.
struct ColliderSettings {
  /// Coulomb friction coefficient of the collider's surface; a cloth–collider pair uses the
  /// geometric mean of this and ClothMaterial::friction.
  Real friction = 0.3;
};

/// When a cloth at rest stops being simulated. A sleeping cloth costs nothing per frame and
/// keeps its positions (its velocities are zero); it wakes when one of its pins is given a new
/// target, when a collider near it moves, appears or disappears, when gravity or wind change,
/// on setState() and on World::wake(). A cloth sleeps only near equilibrium: both its speed and
/// the acceleration of its last frame must stay small, so a cloth that happens to be still while
/// forces pull on it (released from rest, at the top of a swing) keeps moving.
struct SleepSettings {
  bool enabled = true;      ///< allow this cloth to sleep
  Real speed = 2e-3;        ///< m/s, every vertex slower than this...
  /// m/s², ...and no vertex's velocity changed faster than this over the frame (the residual of
  /// M a = f: zero at equilibrium, g for a cloth released from rest)...
  Real acceleration = 0.05;
  Index frames = 30;        ///< ...for this many consecutive frames
};

/// Per-instance settings of a cloth.
struct ClothSettings {
  ForceModel forceModel = ForceModel::BaraffWitkin;  ///< continuum (default) or springs
  ClothMaterial material;         ///< stiffness, density, damping (defaults: cotton curtain)
  MassSpringMaterial springs;     ///< used with ForceModel::MassSpring
  SolverSettings solver;          ///< integrator and solver
  Vec3 translation{0, 0, 0};      ///< m, applied to the model's rest positions (after rotation)
  Mat3 rotation = Mat3::Identity();  ///< rotation applied to the model's rest positions
  std::vector<Index> pinnedVertices;  ///< vertices held at targets (World::setPinTargets)
  /// kg per vertex, replacing material.arealDensity × lumped area (weights sewn into a hem, a
  /// heavy patch, uneven cloth). Empty: masses from the density. Otherwise one finite, positive
  /// mass per vertex of the model.
  std::vector<Real> vertexMasses;
  /// Keeps the cloth from passing through itself (Bridson, Fedkiw & Anderson 2002). Costs a BVH
  /// refit and queries per substep; turn off for cloth that cannot fold onto itself.
  bool selfCollision = true;
  /// Keeps the cloth's faces, not only its vertices, out of every collider but a plane, so a rod
  /// or plank thinner than the triangles cannot pass between the vertices. Costs a box test per
  /// triangle per nearby collider and pass; turn off only for meshes much finer than every collider.
  bool faceContacts = true;
  SleepSettings sleep;  ///< when the cloth at rest stops being simulated
  /// Keeps the cloth from passing through other cloths of the world that have this switch on
  /// too (resolved in every substep with the cloth's own contacts). Costs a bounds test per
  /// substep while the cloths are apart.
  bool collideWithOtherCloths = true;
};

/// A snapshot of a World: time, every cloth's positions, velocities, pin targets and solver warm
/// start, and every collider's motion. World::restoreState() brings a world back to it, after
/// which the world continues bit for bit as it did from the save (replays, networking,
/// rollback). Opaque: compare states through World::stateHash().
class WorldState {
 public:
  WorldState();
  ~WorldState();
  /// A deep copy (a moved-from state copies as empty).
  WorldState(const WorldState&);
  /// A deep copy (a moved-from state copies as empty).
  WorldState& operator=(const WorldState&);
  /// Moves the snapshot; the moved-from state is empty and refused by restoreState().
  WorldState(WorldState&&) noexcept;
  /// Moves the snapshot; the moved-from state is empty and refused by restoreState().
  WorldState& operator=(WorldState&&) noexcept;

 private:
  friend class World;
  struct Data;
  std::unique_ptr<Data> m_data;
};

/// World-wide settings.
struct WorldSettings {
  Vec3 gravity{0.0, -9.81, 0.0};  ///< m/s²
  Vec3 wind{0.0, 0.0, 0.0};       ///< m/s, air velocity felt through ClothMaterial::airDrag
  /// Threads the world's loops run on, the caller's included: 0 = the machine's cores, 1 = serial,
  /// at most TaskSystemSettings::kMaxThreadCount. The same bits for every count. Ignored when
  /// taskSystem is given.
  int threadCount = 0;
  /// The caller's own task system (and so its oneTBB arena), which must outlive the world. Null:
  /// the world makes one with threadCount threads. Nothing else spawns threads.
  TaskSystem* taskSystem = nullptr;
  /// Skip the stages a scene does not need (far colliders, self-collision of cloth that cannot
  /// touch itself, zero bending and damping terms, refits of still parts): the same bits, except
  /// the conservative self-collision cull. Off: every stage runs, to check that. docs/tuning.md.
  bool skipUnneededStages = true;
};

/// Owns cloths and colliders and steps them (see the note at the top of this file).
class World {
 public:
  /// A world, or an error naming the field of `settings` that is wrong (gravity not finite or
  /// beyond kMaxGravity, wind beyond kMaxSpeed, threadCount out of range) and the fix.
  static Result<World> create(const WorldSettings& settings = {});
  /// A world without the check; it makes its own task system unless settings.taskSystem is
  /// given. Invalid settings make every createCloth() fail with the error create() would give.
  explicit World(const WorldSettings& settings = {});
  ~World();
  /// Move-only: handles stay valid in the moved-to world.
  World(World&&) noexcept;
  /// Move-only: handles stay valid in the moved-to world.
  World& operator=(World&&) noexcept;

  /// Adds a cloth. Fails with a message on invalid settings (non-positive density, negative
  /// stiffness, a value beyond kMaxMaterialValue, pins out of range, non-finite pose, a vertex
  /// placed beyond kMaxCoordinate...) or when its estimated memory is not available, leaving the
  /// world unchanged.
  Result<ClothId> createCloth(std::shared_ptr<const ClothModel> model, const ClothSettings& settings);
  /// bytes, an upper bound on the heap a cloth of this size takes in a world through its first
  /// frames (about 1.3 times the measured peak; the shared model not included).
  static std::uint64_t estimatedClothBytes(std::uint64_t vertices, std::uint64_t triangles);
  /// Removes a cloth; its handle (and copies of it) become stale.
  Status destroyCloth(ClothId cloth);

  /// Sets where the pinned vertices are at the end of the next frame (one target per entry of
  /// ClothSettings::pinnedVertices, same order). Pins move linearly across the frame; when every
  /// pin jumps farther than SolverSettings::pinTeleportDistance, or the pins turn rigidly by more
  /// than SolverSettings::pinTeleportAngle, the frame is a teleport and the cloth is carried with
  /// them instead of dragged. Targets must be finite and within kMaxCoordinate; on error nothing
  /// changes.
  Status setPinTargets(ClothId cloth, std::span<const Vec3> targets);
  /// Adds a kinematic collider (plane, sphere, capsule, box or triangle mesh; see
  /// weft/collision). Its motion (pose and velocities) is the shape's own; it moves with those
  /// velocities during each step until setColliderMotion() changes them. Its linear velocity
  /// must be within kMaxSpeed.
  Result<ColliderId> addCollider(const Shape& shape, const ColliderSettings& settings = {});
  /// Removes a collider; its handle becomes stale.
  Status destroyCollider(ColliderId collider);
  /// Sets the collider's pose now and its linear (m/s) and angular (rad/s) velocity for the
  /// following steps. Validated (a linear velocity within kMaxSpeed); on error nothing changes.
  Status setColliderMotion(ColliderId collider, const RigidMotion& motion);
  /// The collider's shape, posed where it is now; valid until the next step or destroy.
  Result<const Shape*> collider(ColliderId collider) const;

  /// Ties pinned vertices of a cloth to a collider, rigidly, at the offsets they have from it
  /// now: from the next step on, their targets follow the collider's pose (a cape on a moving
  /// shoulder, a flag on a turning pole) and setPinTargets() no longer moves them. Each vertex
  /// must be listed in ClothSettings::pinnedVertices; attaching one again moves it to the new
  /// collider. Destroying the collider detaches its vertices, which then stay where they are.
  /// Validated; on error nothing changes.
  Status attachToCollider(ClothId cloth, std::span<const Index> vertices, ColliderId collider);
  /// Frees attached vertices from their colliders; they stay pinned where they are. Vertices
  /// that are not attached are ignored.
  Status detachFromCollider(ClothId cloth, std::span<const Index> vertices);
  /// Number of the cloth's vertices attached to colliders.
  Result<Index> attachedVertexCount(ClothId cloth) const;

  /// N, a force on each vertex of the cloth (one per vertex, in vertex order), applied every
  /// substep until changed; an empty span removes them. Pinned vertices ignore it. Game forces
  /// such as a blast, a hand pulling or a scripted gust go here. Wakes the cloth. Each within
  /// kMaxMaterialValue N; on error nothing changes.
  Status setExternalForces(ClothId cloth, std::span<const Vec3> forces);
  /// m/s, the air velocity every cloth feels through ClothMaterial::airDrag from the next step
  /// on (WorldSettings::wind at creation); wakes every cloth. Must be finite and within
  /// kMaxSpeed; on error nothing changes.
  Status setWind(const Vec3& wind);
  /// m/s, the current air velocity.
  const Vec3& wind() const { return m_settings.wind; }

  /// Replaces a cloth's positions (m) and velocities (m/s), e.g. to start from a draped shape or
  /// to teleport it. Pinned vertices jump with it and their targets are set to the new positions.
  /// Sizes must match the vertex count, every value must be finite, positions within
  /// kMaxCoordinate and velocities within kMaxSpeed; on error nothing changes.
  Status setState(ClothId cloth, std::span<const Vec3> positions, std::span<const Vec3> velocities);
  /// Changes gravity (m/s²) for every cloth and wakes them all. Finite, within kMaxGravity.
  Status setGravity(const Vec3& gravity);
  /// Wakes a sleeping cloth (no effect on an awake one).
  Status wake(ClothId cloth);
  /// True while the cloth sleeps (see SleepSettings).
  Result<bool> isSleeping(ClothId cloth) const;
  /// Current pin targets (the ones the next frame ends at).
  Result<std::vector<Vec3>> pinTargets(ClothId cloth) const;

  /// Advances every cloth by frameDt seconds (> 0, finite). Returns the status flags, also kept
  /// in stats().status.
  StepStatus step(Real frameDt);
  /// Advances by frameDt within a wall-clock budget: the substeps, PCG tolerance and iteration
  /// cap are planned from the measured cost of earlier frames (see StepBudget). A frame that
  /// still overruns is reported (StepStatus::BudgetMissed), never hidden; the plan it ran and
  /// the accuracy it reached (cgResidual, maxStrain, frozenVertices) are in stats().
  /// budget.milliseconds = 0 is the same as step(frameDt). Invalid budget fields are refused
  /// (StepStatus::InvalidInput) and nothing changes.
  StepStatus step(Real frameDt, const StepBudget& budget);
  /// Advances by frameDt running exactly `plan` (e.g. a StepStats::plan recorded by a budgeted
  /// run): the same plan from the same state gives the same bits. Invalid plan fields (negative
  /// or non-finite, a tolerance of 1 or more, more substeps than any cloth's
  /// SolverSettings::maxSubsteps) are refused with StepStatus::InvalidInput and nothing changes.
  StepStatus step(Real frameDt, const StepPlan& plan);
  /// Statistics of the last step().
  const StepStats& stats() const { return m_stats; }
  /// s, simulated time.
  Real time() const { return m_time; }

  /// Read-only positions, normals and indices; valid until the next step() or destroyCloth().
  Result<ClothRenderView> renderView(ClothId cloth) const;
  /// m, current positions.
  Result<std::span<const Vec3>> positions(ClothId cloth) const;
  /// m/s, current velocities.
  Result<std::span<const Vec3>> velocities(ClothId cloth) const;
  /// Substeps per frame that the cloth's settings give for this frame length (after the
  /// stability estimate for explicit integrators, and for the pin targets set for the next frame:
  /// see SolverSettings::substeps).
  Result<Index> plannedSubsteps(ClothId cloth, Real frameDt) const;

  /// Copies everything that decides how the world continues (see WorldState).
  WorldState saveState() const;
  /// Brings the world back to a saved state. The state must come from this world's saveState(),
  /// and its cloths and colliders must still exist (same handles); otherwise an error names the
  /// problem and nothing changes.
  Status restoreState(const WorldState& state);

  /// 64-bit FNV-1a hash of every cloth's positions and velocities, bit for bit: equal hashes
  /// mean (almost surely) bitwise-identical states.
  std::uint64_t stateHash() const;

  /// Number of live cloths.
  Index clothCount() const;
  /// Threads the world's loops run on (1 = serial).
  int threadCount() const;

 private:
  struct ClothSlot;
  struct ColliderSlot;
  const ClothSlot* find(ClothId cloth) const;
  ClothSlot* find(ClothId cloth);
  const ColliderSlot* find(ColliderId collider) const;
  ColliderSlot* find(ColliderId collider);
  void updateAttachedPins(Real frameDt);

  WorldSettings m_settings;
  std::unique_ptr<TaskSystem> m_ownedTasks;  // when the caller gave none
  TaskSystem* m_tasks = nullptr;
  std::vector<std::unique_ptr<ClothSlot>> m_slots;
  std::vector<std::unique_ptr<ColliderSlot>> m_colliderSlots;
  std::vector<ColliderSource> m_colliderSources;  // scratch for step()
  std::vector<Cloth*> m_steppedCloths;            // scratch for step()
  std::vector<Vec3> m_attachedTargets;            // scratch for step()
  // Runs one frame with `plan`; budgetMs > 0 reports a miss; the cost model is refitted from the
  // frame's timings (weight costSmoothing) assuming `defaultTolerance` where the plan has none.
  StepStatus stepWithPlan(Real frameDt, const StepPlan& plan, Real budgetMs, Real costSmoothing,
                          Real defaultTolerance = 1e-3);
  std::unique_ptr<FrameCostModel> m_costModel;  // fitted to measured frames (budgeted steps)
  StepStats m_stats;
  Real m_time = 0;

  std::unique_ptr<SubstepPipeline> m_pipeline;  // every frame's substeps
  std::uint64_t m_identity = 0;  // unique per World, so a state saved elsewhere is refused
  std::string m_settingsError;   // why the settings are invalid (then createCloth refuses)
};

}  // namespace weft
