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
#include <weft/engine/StepStats.h>
#include <weft/threading/TaskSystem.h>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace weft {

struct ColliderFrame;  // internal: a collider as one step sees it

/// Handle to a cloth in a World. Zero-initialised = null.
struct ClothId {
  std::uint32_t index = 0;       ///< slot + 1 (0 = null)
  std::uint32_t generation = 0;  ///< must match the slot's generation
  bool isNull() const { return index == 0; }
  friend bool operator==(const ClothId&, const ClothId&) = default;
};

/// Handle to a collider in a World. Zero-initialised = null.
struct ColliderId {
  std::uint32_t index = 0;       ///< slot + 1 (0 = null)
  std::uint32_t generation = 0;  ///< must match the slot's generation
  bool isNull() const { return index == 0; }
  friend bool operator==(const ColliderId&, const ColliderId&) = default;
};

/// Per-instance settings of a collider.
struct ColliderSettings {
  /// Coulomb friction coefficient of the collider's surface; a cloth–collider pair uses the
  /// geometric mean of this and ClothMaterial::friction.
  Real friction = 0.3;
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
};

/// A snapshot of a World: time, every cloth's positions, velocities, pin targets and solver warm
/// start, and every collider's motion. World::restoreState() brings a world back to it, after
/// which the world continues bit for bit as it did from the save (replays, networking,
/// rollback). Opaque: compare states through World::stateHash().
class WorldState {
 public:
  WorldState();
  ~WorldState();
  WorldState(const WorldState&);
  WorldState& operator=(const WorldState&);
  WorldState(WorldState&&) noexcept;
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
  /// Threads the world's loops run on, the caller's included: 0 = the machine's cores, 1 = serial.
  /// Results are bitwise the same for every count. Ignored when taskSystem is given.
  int threadCount = 0;
  /// The caller's own task system (and so its oneTBB arena), which must outlive the world. Null:
  /// the world makes one with threadCount threads. Nothing else spawns threads.
  TaskSystem* taskSystem = nullptr;
};

class World {
 public:
  explicit World(const WorldSettings& settings = {});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  /// Adds a cloth. Fails with a message on invalid settings (non-positive density, negative
  /// stiffness, pins out of range, non-finite pose...), leaving the world unchanged.
  Result<ClothId> createCloth(std::shared_ptr<const ClothModel> model, const ClothSettings& settings);
  /// Removes a cloth; its handle (and copies of it) become stale.
  Status destroyCloth(ClothId cloth);

  /// Sets where the pinned vertices are at the end of the next frame (one target per entry of
  /// ClothSettings::pinnedVertices, same order). Pins move linearly across the frame.
  Status setPinTargets(ClothId cloth, std::span<const Vec3> targets);
  /// Adds a kinematic collider (plane, sphere, capsule, box or triangle mesh; see
  /// weft/collision). Its motion (pose and velocities) is the shape's own; it moves with those
  /// velocities during each step until setColliderMotion() changes them.
  Result<ColliderId> addCollider(const Shape& shape, const ColliderSettings& settings = {});
  /// Removes a collider; its handle becomes stale.
  Status destroyCollider(ColliderId collider);
  /// Sets the collider's pose now and its linear (m/s) and angular (rad/s) velocity for the
  /// following steps. Validated; on error nothing changes.
  Status setColliderMotion(ColliderId collider, const RigidMotion& motion);
  /// The collider's shape, posed where it is now; valid until the next step or destroy.
  Result<const Shape*> collider(ColliderId collider) const;

  /// Replaces a cloth's positions (m) and velocities (m/s), e.g. to start from a draped shape or
  /// to teleport it. Pinned vertices jump with it and their targets are set to the new positions.
  /// Sizes must match the vertex count and every value must be finite; on error nothing changes.
  Status setState(ClothId cloth, std::span<const Vec3> positions, std::span<const Vec3> velocities);
  /// Current pin targets (the ones the next frame ends at).
  Result<std::vector<Vec3>> pinTargets(ClothId cloth) const;

  /// Advances every cloth by frameDt seconds (> 0, finite). Returns the status flags, also kept
  /// in stats().status.
  StepStatus step(Real frameDt);
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
  /// stability estimate for explicit integrators).
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

  WorldSettings m_settings;
  std::unique_ptr<TaskSystem> m_ownedTasks;  // when the caller gave none
  TaskSystem* m_tasks = nullptr;
  std::vector<std::unique_ptr<ClothSlot>> m_slots;
  std::vector<std::unique_ptr<ColliderSlot>> m_colliderSlots;
  std::vector<ColliderFrame> m_colliderFrames;  // scratch for step()
  std::vector<RigidMotion> m_colliderStartMotions;  // scratch for step()
  StepStats m_stats;
  Real m_time = 0;
  std::uint64_t m_identity = 0;  // unique per World, so a state saved elsewhere is refused
};

}  // namespace weft
