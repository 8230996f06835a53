// The cantilever bending test (ASTM D1388 option A; Peirce, "The handle of cloth as a measurable
// quantity", J. Textile Inst. 21, 1930): a 25 mm strip slid over a platform's edge bends under
// its own weight; the overhang O at which the chord from the edge to the tip drops 41.5° below
// the horizontal gives the bending length c = O / 2 (D1388's definition, from Peirce's
// c = l · (cos(θ/2) / (8 tan θ))^(1/3), which is ½ at 41.5°).
//
// Here the part on the platform is pinned (two rows behind the edge fix the slope there, as the
// platform and the strip's own weight do), the overhang hangs free; chordAngle() is read once the
// strip is still. bendingLength() repeats that for a few overhangs and interpolates to 41.5°.
// elasticaLoad() is the exact inextensible elastica of a heavy cantilever, the theory the
// simulated strip is held to: a strip of rigidity D (N·m) and weight w = ρ_A g (N/m²) reaches a
// chord angle θ at the overhang l with w l³ / D = elasticaLoad(θ).
#pragma once

#include <weft/engine/World.h>

namespace weft {

/// Settings of one cantilever.
struct CantileverSettings {
  Real overhang = 0.04;          ///< m, l: the strip beyond the platform's edge
  Real width = 0.025;            ///< m, the strip's width (D1388: 25 mm)
  Index overhangSegments = 20;   ///< mesh segments along the overhang (square cells across)
  ClothMaterial material;        ///< the fabric tested
  SolverSettings solver;         ///< the engine's defaults
};

/// A World with the strip in it, flat and at rest at t = 0.
class CantileverScene {
 public:
  static constexpr Real kFrameDt = 1.0 / 60.0;  ///< s
  /// rad, D1388's angle: 41.5°, where Peirce's bending length is half the overhang.
  static constexpr Real kTestAngle = 41.5 * 3.14159265358979323846 / 180;

  /// Builds the scene; fails on invalid settings, with the reason.
  static Result<CantileverScene> create(const CantileverSettings& settings = {});

  /// Advances one frame of 1/60 s.
  StepStatus stepFrame() { return m_world->step(kFrameDt); }
  /// rad, the angle below the horizontal of the chord from the edge to the tip (the tip row's mean).
  Real chordAngle() const;
  /// m/s, the fastest vertex of the strip.
  Real largestSpeed() const;
  /// The world that holds the strip, for stats and state.
  World& world() { return *m_world; }

  /// w l³ / D of the exact heavy elastica whose tip chord hangs `chordAngle` rad below the
  /// horizontal (clamped level at the edge, free tip); 8 at 41.5° in Peirce's approximation.
  static Real elasticaLoad(Real chordAngle);

  /// D1388's bending length (m) of `material` on this strip: settles (until every vertex is
  /// slower than 0.1 mm/s, at most `seconds`) at a few overhangs, interpolates the overhang O at 41.5° and returns O / 2; NaN when no overhang
  /// between 1 and 40 cm brackets the angle.
  static Real bendingLength(const CantileverSettings& settings, Real seconds = 10.0);

 private:
  CantileverScene() = default;
  std::unique_ptr<World> m_world;
  ClothId m_cloth;
  std::vector<Index> m_tip;
  Index m_edgeVertex = 0;
};

}  // namespace weft
