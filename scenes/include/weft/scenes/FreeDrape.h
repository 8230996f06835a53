// The free drape: a square sheet hanging from its top edge, released from a tilt and swinging
// under gravity, with nothing to touch. Smooth and nonlinear (a swing of ±30°, tension that
// varies down the sheet), it measures an integrator's order and damping on cloth itself; the
// tests of the default dynamics and weft-error-time --scene drape share it. Released from higher
// up (π/2: horizontal) the falling hem buckles the sheet, and runs at h and h/2 stop converging
// to each other (2 cm apart at h = 1/1920 s): not a scene to read an order from.
//
//        pinned top edge (y = 0, along x)
//   ─────●───●───●───●─────
//        \                 the sheet, tilted by releaseAngle from hanging straight down
//         \                (π/2: horizontal), flat and at rest at t = 0
#pragma once

#include <weft/engine/World.h>

#include <memory>

namespace weft {

/// Settings of a free drape.
struct FreeDrapeSettings {
  Real size = 1.0;                 ///< m, side of the square sheet
  Index verticesPerSide = 21;      ///< grid vertices along each side (5 cm spacing at 1 m)
  Real releaseAngle = 0.5235987755982988;  ///< rad from the vertical (π/6); π/2 = horizontal
  ClothMaterial material;          ///< the engine's default material
  SolverSettings solver;           ///< the engine's default solver
  int threadCount = 1;             ///< threads of the scene's world (0 = all cores)
};

/// A World with the sheet in it.
class FreeDrapeScene {
 public:
  static constexpr Real kFrameDt = 1.0 / 60.0;  ///< s, one frame

  /// Builds the scene; fails on invalid settings (a size or vertex count out of range).
  static Result<FreeDrapeScene> create(const FreeDrapeSettings& settings = {});

  /// Advances one frame (substeps as the solver settings plan them).
  StepStatus stepFrame() { return m_world->step(kFrameDt); }
  /// The world that holds the sheet.
  World& world() { return *m_world; }
  /// The sheet's cloth in world().
  ClothId cloth() const { return m_cloth; }
  /// The sheet's mesh.
  const ClothModel& model() const { return *m_model; }
  /// Positions now (m), one per vertex.
  std::span<const Vec3> positions() const { return m_world->positions(m_cloth).value(); }

 private:
  FreeDrapeScene() = default;
  std::shared_ptr<const ClothModel> m_model;
  std::unique_ptr<World> m_world;
  ClothId m_cloth;
};

}  // namespace weft
