// The curtain benchmark: the reference scene every test and benchmark shares
// (docs/curtain-benchmark.md).
//
// A 2.0 m × 1.5 m cotton curtain in the z = 0 plane (x from −1 to +1, y from 0.5 to 2.0), its
// top row pinned to a rod. Script over 10 s at 60 frames/s:
//   0–1 s settle · 1–2 s a sphere (r = 0.25 m, at x = 0.3, y = 1.1) pushes into the curtain
//   from z = −0.5 to z = +0.3, 2–3 s it withdraws ·
//   4–6 s the rod pins slide toward the left end until the curtain is gathered to 30 % of its
//   width · 6–8 s hold · 8–10 s open again.
// The cloth starts with gentle pleats of ±5 mm out of the plane (CurtainSettings::initialWaviness)
// so that gathering folds it out of plane, as a real curtain does, instead of crumpling it in-plane.
// Sizes ×1, ×4, ×16, ×64 keep the physical size and refine the grid (41 × 31 up to 321 × 241).
#pragma once

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <memory>
#include <span>

namespace weft {

/// A named interval of the curtain's script (for charts and reports).
struct CurtainPhase {
  Real begin = 0;         ///< s, start of the phase
  Real end = 0;           ///< s, end of the phase
  const char* name = "";  ///< what happens, e.g. "sphere pushes"
};

/// Settings of a curtain run.
struct CurtainSettings {
  Index size = 1;  ///< refinement: 1, 4, 16 or 64 times the triangles of the 41 × 31 curtain
  ForceModel forceModel = ForceModel::BaraffWitkin;  ///< internal forces
  ClothMaterial material = cottonFabric();  ///< the cotton preset (strain limit 0.10)
  SolverSettings solver;     ///< integrator and solver
  bool pinScript = true;     ///< run the rod script (gather and re-open); false keeps the rod still
  /// m, amplitude of gentle pleats the curtain starts with (z = a·sin(2πx / 0.25 m), fading to 0
  /// at the rod). A real curtain never hangs perfectly flat, and a perfectly planar one has no
  /// way to choose a side when the rod gathers it: it can only crumple in its own plane.
  Real initialWaviness = 0.005;
  bool sphere = true;        ///< the pushing sphere (and the floor far below) as colliders
  bool selfCollision = true; ///< keep the curtain from passing through itself
  int threadCount = 0;                ///< threads of the scene's world (0 = all cores, 1 = serial)
  TaskSystem* taskSystem = nullptr;   ///< or the caller's task system (overrides threadCount)
  bool skipUnneededStages = true;     ///< WorldSettings::skipUnneededStages
  bool sleep = true;                  ///< ClothSettings::sleep.enabled
};

/// The curtain scene: a World with one cloth and the pin script.
class CurtainScene {
 public:
  static constexpr Real kFrameDt = 1.0 / 60.0;  ///< s, one frame
  static constexpr Index kFrames = 600;          ///< frames of the full 10 s script
  static constexpr Real kGatheredFraction = 0.3; ///< width of the gathered curtain / full width

  /// Builds the scene; fails on a size other than 1, 4, 16, 64 or on invalid settings.
  static Result<CurtainScene> create(const CurtainSettings& settings = {});

  /// Moves the rod to where the script puts it at the end of the next frame, then steps.
  StepStatus stepFrame();
  /// The same, within a frame budget (World::step(frameDt, budget)).
  StepStatus stepFrame(const StepBudget& budget);
  /// The same, running a given plan (World::step(frameDt, plan)), e.g. to replay a budgeted run.
  StepStatus stepFrame(const StepPlan& plan);

  /// The world the curtain runs in.
  World& world() { return *m_world; }
  /// The world the curtain runs in.
  const World& world() const { return *m_world; }
  /// The curtain's handle.
  ClothId cloth() const { return m_cloth; }
  /// The pushing sphere (null handle when CurtainSettings::sphere is false).
  ColliderId sphere() const { return m_sphere; }
  /// The floor plane at y = 0 (null handle when CurtainSettings::sphere is false).
  ColliderId floor() const { return m_floor; }
  static constexpr Real kSphereRadius = 0.25;  ///< m
  /// Where the script puts the sphere's centre at time t (s).
  static Vec3 spherePosition(Real t);
  /// The curtain's model (its grid at this size).
  const ClothModel& model() const { return *m_model; }
  /// The same model, shared (to build another cloth from it).
  std::shared_ptr<const ClothModel> sharedModel() const { return m_model; }
  /// Frames stepped so far.
  Index frame() const { return m_frame; }
  /// Sets the script's frame counter (after World::restoreState() to a save taken at `frame`).
  void rewindTo(Index frame) { m_frame = frame; }

  /// The script's phases in time order, 0 to 10 s: the intervals of spherePosition() and
  /// pinTarget(), and the rest between them.
  static std::span<const CurtainPhase> phases();

  /// Grid vertices along the width and height for a size (41 × 31 for size 1).
  static std::array<Index, 2> gridSize(Index size);
  /// Where the script puts a rod pin that starts at restPosition, at time t (s).
  static Vec3 pinTarget(const Vec3& restPosition, Real t);

 private:
  CurtainScene() = default;
  void scriptFrame();  // sets the rod and sphere for the coming frame

  std::unique_ptr<World> m_world;
  std::shared_ptr<const ClothModel> m_model;
  ClothId m_cloth;
  ColliderId m_sphere, m_floor;
  Vec3Array m_pinRest;          // rest positions of the pinned vertices
  Vec3Array m_targets;          // scratch: this frame's targets
  bool m_pinScript = true;
  Index m_frame = 0;
};

}  // namespace weft
