// ScriptedScene: a World built from a SceneDescription, stepped frame by frame with its scripts.
//
// Every frame, before World::step(), each scripted pin group gets the targets its keyframes give
// at the frame's end time, the wind (if it has keyframes) the value at that time, and each
// keyframed collider gets the velocities that carry it from
// where it is to where its keyframes put it at that time (the way CurtainScene moves its sphere):
// the world moves colliders with their velocities during the step, so the pose follows the track
// without a jump. Colliders without keyframes keep their constant velocities.
//
// Keyframe evaluation at time t (see SceneFile.h): the segment is the one with t0 < t ≤ t1, the
// value v0 + (v1 − v0)·ease((t − t0) / (t1 − t0)); rotations are slerped.
#pragma once

#include <weft/engine/World.h>
#include <weft/scenes/SceneFile.h>

#include <memory>
#include <vector>

namespace weft {

/// Options for building a scene's world.
struct ScriptedSceneSettings {
  int threadCount = 0;               ///< threads of the world (0 = all cores, 1 = serial)
  TaskSystem* taskSystem = nullptr;  ///< or the caller's task system (overrides threadCount)
};

/// Smoothstep or identity on a fraction in [0, 1] (clamped).
Real ease(Easing easing, Real fraction);
/// Where a pin script puts a pin that starts at `start`, at time `t` (s).
Vec3 pinTarget(const PinScript& script, const Vec3& start, Real t);
/// Where a collider's keyframes put it at time `t` (s); keyframes must not be empty.
Pose keyframePose(const ColliderDescription& collider, Real t);
/// The wind (m/s) the scene's wind keyframes give at time `t` (s); `wind` when it has none.
Vec3 windAt(const SceneDescription& scene, Real t);

/// A World built from a scene description, plus the scripts that drive it.
class ScriptedScene {
 public:
  /// Builds the world (cloths, then colliders, then initial pleats, then pins riding on
  /// colliders, which keep the offsets they have after the pleats). Errors name the cloth or
  /// collider by its JSON path and carry the engine's message.
  static Result<ScriptedScene> create(SceneDescription description,
                                      const ScriptedSceneSettings& settings = {});

  /// Sets this frame's pin targets and collider velocities, then steps one frame. A target or
  /// motion the world refuses (non-finite) is skipped and flagged StepStatus::InvalidInput.
  StepStatus stepFrame();

  /// The world the scene runs in (add cloths or colliders, read state, save and restore).
  World& world() { return *m_world; }
  /// The world the scene runs in.
  const World& world() const { return *m_world; }
  /// The description the scene was built from.
  const SceneDescription& description() const { return m_description; }
  /// Handle of cloth k (file order).
  ClothId cloth(std::size_t k) const { return m_cloths[k]; }
  /// Handle of collider k (file order).
  ColliderId collider(std::size_t k) const { return m_colliders[k]; }
  /// Number of cloths of the file.
  std::size_t clothCount() const { return m_cloths.size(); }
  /// Number of colliders of the file.
  std::size_t colliderCount() const { return m_colliders.size(); }
  /// Frames stepped so far.
  Index frame() const { return m_frame; }
  /// s, length of one frame.
  Real frameDt() const { return m_description.frameDt; }

  /// The pin targets of cloth k at time t (one per ClothSettings::pinnedVertices entry), written
  /// into `targets` (resized).
  void pinTargetsAt(std::size_t k, Real t, std::vector<Vec3>& targets) const;

 private:
  ScriptedScene() = default;

  SceneDescription m_description;
  std::unique_ptr<World> m_world;
  std::vector<ClothId> m_cloths;
  std::vector<ColliderId> m_colliders;
  std::vector<Vec3Array> m_pinStarts;  // per cloth: start positions of its pins, in pin order
  std::vector<bool> m_scripted;        // per cloth: some pin group has a script
  Vec3Array m_targets;                 // scratch for stepFrame()
  Index m_frame = 0;
};

}  // namespace weft
