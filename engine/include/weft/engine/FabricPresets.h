// Fabric presets: ClothMaterial values for common woven fabrics, by name.
//
// Every stiffness is per unit width, in the units of Material.h, so a preset works on any mesh
// resolution. Where each number comes from is written beside it in FabricPresets.cpp; the short
// version:
//   - areal density: fabric weights, the Wang, Ramamoorthi & O'Brien 2011 measurement database
//     ("Data-driven elastic models for cloth", as shipped with ARCSim) where a matching fabric
//     exists, otherwise typical catalogue weights (g/m²);
//   - bending and shear: Kawabata KES-F ranges (B in gf·cm²/cm, G in gf/(cm·deg)) converted to
//     SI, 1 gf·cm²/cm = 9.80665e-5 N·m and 1 gf/(cm·deg) = 56.19 N/m per radian of shear;
//   - stretch: the low-strain slope of the Wang et al. 2011 fits, which, like the curtain's
//     260 N/m, is the small-load regime; linear in the presets, with a strain limit [EST];
//   - damping, friction and contact thickness: engineering estimates (no measurement behind them).
// stiffeningFabricPreset() adds the fabric's KES tensile test (strain EMT at 500 gf/cm,
// linearity LT): past a knee the stretch stiffens to kilonewtons per metre (the biphasic law of
// ClothMaterial::stretchKneeStrain), and the strain limit moves to EMT. It is not the presets'
// default yet: the contact pipeline does not hold the lower limits in every stress scene.
// "cotton" is ClothMaterial{} (the curtain's material) with a strain limit of 0.10, and a test
// keeps it so. The others are scaled estimates; treat them as starting points, not measurements.
#pragma once

#include <weft/Result.h>
#include <weft/engine/Material.h>

#include <span>
#include <string_view>

namespace weft {

/// Light cotton (lawn/shirting): ClothMaterial{}, the curtain's material, with strainLimit 0.10.
ClothMaterial cottonFabric();
/// Wool suiting: heavier, softer in shear, stiffer in bending than cotton.
ClothMaterial woolFabric();
/// Plain polyester (jacket/lining weave): light, springy in bending.
ClothMaterial polyesterFabric();
/// Silk (habutai/crêpe de Chine): very light and limp, low friction.
ClothMaterial silkFabric();
/// 11 oz denim: heavy, stiff in stretch (weft stronger than warp), bending and shear.
ClothMaterial denimFabric();
/// Medium linen: stiff in bending and shear for its weight.
ClothMaterial linenFabric();

/// Names accepted by fabricPreset(), lowercase: cotton, wool, polyester, silk, denim, linen.
std::span<const std::string_view> fabricPresetNames();

/// The preset of that name (ASCII case-insensitive). An unknown name fails with a message that
/// lists the valid names.
Result<ClothMaterial> fabricPreset(std::string_view name);

/// The preset of that name with its KES tensile test: linear up to a knee, stiffening past it so
/// that the tension is 490 N/m at the fabric's EMT with linearity LT, and strainLimit = EMT.
/// Cotton: knee 1.2 %, 15.4 kN/m from 2.4 %, limit 0.05. Unknown names fail as fabricPreset().
Result<ClothMaterial> stiffeningFabricPreset(std::string_view name);

}  // namespace weft
