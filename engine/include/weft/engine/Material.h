// Cloth materials in physical units, and the choice of force model.
//
// Stiffnesses are per unit width, so they do not change with mesh resolution:
// stretch and shear in N/m (membrane stiffness: force per metre of cloth per unit strain),
// bending in N·m (moment per metre of cloth per unit curvature). Damping acts on the rate of the
// same strains (Baraff & Witkin 1998, §2.3): a stiffness k with damping k_d behaves like a
// Rayleigh damper of time constant k_d / k.
//
// The defaults are the curtain's cotton (docs/curtain-benchmark.md) without a strain limit; the
// fabric presets (FabricPresets.h) give common fabrics, limits included.
#pragma once

#include <weft/Math.h>

namespace weft {

/// How the Baraff–Witkin model discretises bending (both take the same D in N·m).
enum class BendingModel {
  /// Quadratic energy D/2 |∇²x|² from a per-vertex surface Hessian (plate with Poisson ratio 0,
  /// after Bergou et al. 2006): the continuum D/2 κ² in every direction, constant Hessian. Default.
  Isometric,
  /// Dihedral angle per interior edge (Baraff & Witkin 1998), weight 3 l²/(A_A + A_B): handles
  /// strongly curved rest shapes, but 2–3× too stiff along grid lines and ≈ 9× along the split
  /// diagonal of a regular grid.
  Dihedral,
};

/// Continuum cloth material for the Baraff–Witkin model (and the mass to give every vertex).
struct ClothMaterial {
  Real arealDensity = 0.15;           ///< kg/m², mass per rest area; lumped to vertices
  Real warpStretchStiffness = 260.0;  ///< N/m, resistance to stretching along the warp (u)
  Real weftStretchStiffness = 260.0;  ///< N/m, resistance to stretching along the weft (v)
  Real shearStiffness = 100.0;        ///< N/m, resistance to in-plane shear (angle change of u, v)
  Real bendingStiffness = 2.3e-6;     ///< N·m, resistance to curvature; 0 turns bending off
  BendingModel bendingModel = BendingModel::Isometric;  ///< discretisation of the bending energy
  Real warpRestScale = 1.0;           ///< rest length factor along the warp (<1 pre-tensions)
  Real weftRestScale = 1.0;           ///< rest length factor along the weft (<1 pre-tensions)
  Real stretchDamping = 0.5;          ///< N·s/m, damps the stretch rate (≈ 2 ms Rayleigh time)
  Real shearDamping = 0.2;            ///< N·s/m, damps the shear rate
  Real bendingDamping = 5e-9;         ///< N·m·s, damps the bending rate
  Real airDrag = 0.1;                 ///< N·s/m³, linear drag per area on velocity relative to air
  Real thickness = 0.003;             ///< m, contact thickness (collision)
  Real friction = 0.3;                ///< Coulomb friction coefficient (collision)
  /// Strain l / l_rest − 1 that no mesh edge exceeds at the end of a step (strain limiting,
  /// Provot 1995; woven fabric is nearly inextensible past ~10 %). Lower feels stiffer and costs
  /// limiter iterations. 0 or infinity = off (default); the fabric presets set it (cotton 0.10).
  Real strainLimit = 0.0;
  /// Fibre strain at which the yarns have straightened and the stretch stiffness starts to rise
  /// towards the stiffened values below (reached at twice this strain): woven fabric's biphasic
  /// tension. 0 or infinity = linear stretch (default); stiffeningFabricPreset() sets it.
  Real stretchKneeStrain = 0.0;
  /// N/m, warp stretch stiffness past the knee (stretchKneeStrain); at least warpStretchStiffness.
  Real warpStiffenedStretchStiffness = 0.0;
  /// N/m, weft stretch stiffness past the knee (stretchKneeStrain); at least weftStretchStiffness.
  Real weftStiffenedStretchStiffness = 0.0;
};

/// The classic mass-spring network (Provot 1995): one stiffness per spring family.
struct MassSpringMaterial {
  Real structuralStiffness = 260.0;  ///< N/m per spring, along warp and weft
  Real shearStiffness = 100.0;       ///< N/m per spring, along diagonals
  Real flexionStiffness = 2.0;       ///< N/m per spring, skip-one springs that resist bending
  Real structuralDamping = 0.5;      ///< N·s/m per spring, on the spring's length rate
  Real shearDamping = 0.2;           ///< N·s/m per spring
  Real flexionDamping = 0.004;       ///< N·s/m per spring
};

/// Which internal forces a cloth uses.
enum class ForceModel {
  BaraffWitkin,  ///< continuum stretch, shear and bending (ClothMaterial::bendingModel); default
  MassSpring,    ///< structural, shear and flexion springs
};

/// Strain past ClothMaterial::strainLimit a frame may end with before the step reports
/// StepStatus::StrainLimitExceeded: the limiter stops within 0.001, and the collision passes after
/// it may stretch an edge a little more.
inline constexpr Real kStrainLimitSlack = 0.01;

}  // namespace weft
