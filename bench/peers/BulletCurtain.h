// BulletCurtain: the curtain (weft::CurtainScene) rebuilt in Bullet's soft body (btSoftBody, the
// position-based mass-spring cloth of btSoftRigidDynamicsWorld), for weft-vs-bullet.
//
// The scene follows weft::CurtainScene, not a Bullet demo: the same 2.0 m × 1.5 m patch with the
// same grid (btSoftBodyHelpers::CreatePatch at 41 × 31, 81 × 61 or 161 × 121 nodes, node index =
// row · columns + column as in Weft), the same 0.45 kg, the same ±5 mm starting pleats, the top
// row moved along CurtainScene::pinTarget and a kinematic sphere (r = 0.25 m) moved along
// CurtainScene::spherePosition. Every Bullet setting, and why it was chosen, is in the settings
// struct below and in bench/peers/README.md.
//
// Bullet headers stay in BulletCurtain.cpp: Bullet is built in single precision (Debian's default
// libraries, the build games use), and nothing of it leaks into Weft's double-precision types.
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>

#include <memory>
#include <string>
#include <vector>

namespace weft {

/// How Bullet's curtain is set up. Defaults are the choices documented in README.md.
struct BulletCurtainSettings {
  Index size = 1;                 ///< 1, 4, 16 (or 64): the grid of CurtainScene::gridSize
  int positionIterations = 1;     ///< Bullet's piterations (its default is 1); raise for stiffness
  int substeps = 1;               ///< Bullet steps per 1/60 s frame (fixed step = frame / substeps)
  bool selfCollision = false;     ///< cluster self-collision (CL_SS + CL_SELF, one cluster per face)
  /// Linear stiffness of the mesh links, Bullet's kLST in [0, 1]: 1, the stiffest, because cloth
  /// barely stretches and PBD can only get softer than its constraints.
  double stretchStiffness = 1.0;
  /// Fraction of the bending links' violation removed per frame (after all iterations), in
  /// [0, 1]. Turned into Bullet's per-iteration kLST by 1 − (1 − k)^(1/n) (Müller et al. 2007,
  /// §3.3), so that bending does not stiffen as the sweep raises the iteration count.
  double bendingStiffnessPerFrame = 0.1;
  /// Bullet's kSSHR_CL: fraction of a cloth–cloth cluster contact's depth resolved per step
  /// (Bullet's default 0.5).
  double selfContactHardness = 0.5;
  /// m, the soft body's collision margin (contact thickness); 0 = a fifth of the grid spacing
  /// (1 cm at ×1, 5 mm at ×4, 2.5 mm at ×16), so that flat neighbours two faces apart stay out of
  /// each other's margins.
  double collisionMargin = 0;
  double sdfVoxelSize = 0.02;     ///< m, cell of Bullet's sparse signed-distance field of the sphere
  double friction = 0.3;          ///< Bullet's kDF, Weft's friction coefficient
  /// 1/s, velocity damping rate; Weft's air drag 0.1 N·s/m³ over 0.15 kg/m² is 0.67/s. Bullet's
  /// kDP per step is 1 − exp(−rate · dt).
  double dampingRate = 0.1 / 0.15;
};

/// The curtain in Bullet: build, step frames, read positions.
class BulletCurtain {
 public:
  /// Builds the scene; fails on a size CurtainScene does not offer or on settings out of range.
  static Result<std::unique_ptr<BulletCurtain>> create(const BulletCurtainSettings& settings);
  ~BulletCurtain();
  BulletCurtain(const BulletCurtain&) = delete;
  BulletCurtain& operator=(const BulletCurtain&) = delete;

  /// One 1/60 s frame: one stepSimulation call of `substeps` fixed steps.
  void stepFrame();
  /// Current node positions, converted to double.
  void readPositions(Vec3Array& positions) const;
  /// Current node velocities (m/s), converted to double.
  void readVelocities(Vec3Array& velocities) const;
  /// Three node indices per face, from Bullet's own face list.
  const std::vector<Index>& indices() const { return m_indices; }
  /// The flat patch before the pleats: the rest state of every link.
  const Vec3Array& restPositions() const { return m_restPositions; }
  /// Links (mesh edges plus bending links), faces, clusters: a line for the report.
  std::string describe() const;

 private:
  struct Bullet;  // the Bullet objects, defined in BulletCurtain.cpp
  BulletCurtain();

  std::unique_ptr<Bullet> m_bullet;
  std::vector<Index> m_indices;
  Vec3Array m_restPositions;
};

}  // namespace weft
