// The Cusick drape test (Cusick, "The measurement of fabric drape", J. Textile Inst. 59, 1968;
// BS 5058): a 30 cm disc of fabric laid flat and clamped between two 18 cm discs; the ring
// that overhangs falls into folds under its own weight, and the drape coefficient
//     DC = (A_shadow − A_support) / (A_specimen − A_support)
// compares the area of its shadow seen from above with the flat disc's (1: it stays flat; the
// limpest fabrics reach about 0.2).
//
// The specimen is an irregular mesh made here, not a grid, so that no mesh direction chooses where
// the folds go: rings of vertices every ~√3/2 spacing, each with its own count (~2πr / spacing),
// a random turn and a jitter of every vertex, zipped into triangles ring to ring; the support
// circle and the edge are rings of their own so that the clamp and the hem are exact circles.
// The clamped disc is pinned (the instrument holds it between the discs); nothing else is touched
// but the cloth itself (self-collision on).
#pragma once

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <cstdint>
#include <memory>

namespace weft {

/// Settings of a Cusick drape test.
struct CusickDrapeSettings {
  Real specimenRadius = 0.15;   ///< m, the fabric disc (30 cm across)
  Real supportRadius = 0.09;    ///< m, the clamping discs (18 cm across)
  Real spacing = 0.0075;        ///< m, the mesh's typical edge length
  std::uint32_t seed = 1;       ///< the mesh's irregularity: another seed, another mesh
  ClothMaterial material = cottonFabric();  ///< the fabric tested
  SolverSettings solver;        ///< the engine's defaults
  int threadCount = 1;          ///< threads of the scene's world (0 = all cores)
};

/// The irregular disc mesh of a Cusick test in the horizontal plane y = 0, with material
/// coordinates (warp along x, weft along z). Fails on radii or a spacing that make no mesh.
Result<TriangleMesh> cusickDiscMesh(const CusickDrapeSettings& settings);

/// A World with the specimen clamped in it, flat and at rest at t = 0.
class CusickDrapeScene {
 public:
  static constexpr Real kFrameDt = 1.0 / 60.0;  ///< s, one frame

  /// Builds the scene; fails on invalid settings, with the reason.
  static Result<CusickDrapeScene> create(const CusickDrapeSettings& settings = {});

  /// Advances one frame of 1/60 s.
  StepStatus stepFrame() { return m_world->step(kFrameDt); }
  /// The drape coefficient of the shape now: its shadow from above rasterised at 0.5 mm.
  Real drapeCoefficient() const;
  /// m/s, the fastest hem (edge-ring) vertex: the drape has settled when the hem stops creeping.
  Real hemSpeed() const;
  /// The world that holds the disc and the pedestal.
  World& world() { return *m_world; }
  /// The disc's cloth in world().
  ClothId cloth() const { return m_cloth; }
  /// The disc's mesh (irregular).
  const ClothModel& model() const { return *m_model; }

 private:
  CusickDrapeScene() = default;
  std::shared_ptr<const ClothModel> m_model;
  std::unique_ptr<World> m_world;
  ClothId m_cloth;
  std::vector<Index> m_hem;
  Real m_specimenRadius = 0, m_supportRadius = 0;
};

}  // namespace weft
