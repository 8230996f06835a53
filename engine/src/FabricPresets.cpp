// Fabric presets. Sources and conversions, once, for every number below:
//
//  [W11] Wang, Ramamoorthi & O'Brien, "Data-driven elastic models for cloth: modeling and
//        measurement", SIGGRAPH 2011: measured density (kg/m²) and piecewise-linear stretch fits
//        of ten fabrics, as distributed with ARCSim (materials/*.json: "density", "stretching"
//        rows C11 C12 C22 C33 per strain sample). ARCSim doubles the table when it loads it and
//        uses E = a/2 · k0 · G00² with the Green strain G ≈ ε, so the Baraff–Witkin stiffness of
//        Material.h (E = a/2 · k · ε²) is k ≈ 2·C11 (warp) and 2·C22 (weft) at the first sample.
//  [KES] Kawabata KES-F low-stress measurements as reported in the textile literature (e.g. the
//        denim table of Hindawi J. Textiles 2016, article 4614168: B = 0.14–0.23 gf·cm²/cm,
//        G = 1.5–3.4 gf/(cm·deg); typical ranges for shirting, suiting and silk fabrics from the
//        same literature). Conversions: B [gf·cm²/cm] × 9.80665e-5 = D [N·m];
//        G [gf/(cm·deg)] × 0.980665 N/m × 180/π = 56.19 N/m per radian of shear, which is the
//        shear stiffness of Material.h (E = a/2 · k · γ² for a small shear angle γ).
//  [EST] Estimate: no measurement behind it, chosen to sit in the range of its neighbours.
//
// Damping is not measured by either source. Every preset keeps the curtain's Rayleigh time
// constants (damping / stiffness: ≈ 1.9 ms stretch, 2 ms shear, 2.2 ms bending), so a preset
// damps its own stiffness the way cotton does. Air drag is the curtain's 0.1 N·s/m³ [EST].
// Thickness is the collision margin (ClothMaterial::thickness), not the caliper thickness of the
// fabric (KES T ≈ 0.3–1.1 mm); it grows with the fabric's weight [EST]. Friction is the
// cloth-on-cloth Coulomb coefficient, 0.2 (silk) to 0.35 (wool, linen, denim) [EST].
//  [KES-T] Kawabata's tensile test (KES-FB1): a strip stretched to 500 gf/cm (490 N/m); EMT is
//        its strain at that load, LT = WT / (½ · 490 N/m · EMT) the linearity of the curve (1: a
//        straight line; woven fabric 0.55–0.75: soft while the crimp straightens, stiff after).
//        Typical apparel ranges as reported in the textile literature (Kawabata, The
//        Standardization and Analysis of Hand Evaluation, 1980; Hu & Chan, Textile Res. J. 68,
//        1998): shirting and lawn EMT 3–6 %, worsted suiting 4–8 %, polyester wovens 2–5 %, silk
//        habutai and crêpe 4–10 %, denim 2–5 % (warp stiffer), linen 2–4 %.
//
// Stretch beyond the low-strain regime (ClothMaterial::stretchKneeStrain and the stiffened
// stiffnesses): the biphasic law of forces/StretchLaw.h keeps each preset's low-strain slope up to
// a knee and reproduces its KES tensile test beyond: the tension reaches 490 N/m at EMT, and the
// curve's linearity is LT (biphasicFromKes below solves for the knee and the stiffened slopes).
// Strain limit of the stiffening presets: EMT, where the measured range of the tensile test
// ends. The material carries 490 N/m there, a load no cloth scene applies, so the limiter is a
// safety net for numerical overshoot, not what holds the cloth.
// Strain limit of the linear presets (ClothMaterial::strainLimit): where the fabric leaves the
// low-strain regime its stretch stiffness was fitted in. Woven fabrics reach that at a few to
// ~10 % (Provot 1995 uses 10 %); crimped wool a little later, tightly woven heavy twill and flax
// earlier. All [EST]: neither source measures it.
#include <weft/engine/FabricPresets.h>

#include "forces/StretchLaw.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <string>

namespace weft {
namespace {

// Rayleigh time constants of the curtain material (ClothMaterial{}): damping / stiffness.
constexpr Real kStretchDampingTime = 0.5 / 260.0;  // s
constexpr Real kShearDampingTime = 0.2 / 100.0;    // s
constexpr Real kBendingDampingTime = 5e-9 / 2.3e-6;  // s

// gf·cm²/cm → N·m and gf/(cm·deg) → N/m per radian (see the note at the top).
constexpr Real kBendingFromKes = 9.80665e-5;
constexpr Real kShearFromKes = 0.980665 * 180.0 / 3.14159265358979323846;

// KES-FB1's test load: 500 gf/cm in N/m.
constexpr Real kKesTestTension = 500 * 9.80665e-3 / 0.01;

// The slope k₁ past 2 ε_k that brings the tension to the test load at emt ≥ 2 ε_k: there
// T = k₀ emt + (k₁ − k₀)(emt − 3 ε_k / 2) (forces/StretchLaw.h).
Real stiffenedSlope(Real lowStiffness, Real knee, Real emt) {
  return lowStiffness + (kKesTestTension - lowStiffness * emt) / (emt - 1.5 * knee);
}

// The knee of StretchLaw (forces/StretchLaw.h) whose curve from 0 to the extensibility `emt` has
// the linearity `linearity` (LT) with the warp's low-strain stiffness k₀, the tension reaching
// the test load at emt: LT(ε_k) falls from 1 (ε_k → 0) as the knee moves up, so bisection finds it.
Real kneeFromKes(Real lowStiffness, Real emt, Real linearity) {
  const auto lawLinearity = [&](Real knee) {
    const StretchLaw law{lowStiffness, knee, stiffenedSlope(lowStiffness, knee, emt)};
    return stretchResponse(law, emt).energyDensity / (0.5 * kKesTestTension * emt);
  };
  Real low = 1e-6 * emt, high = 0.5 * emt;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Real middle = 0.5 * (low + high);
    (lawLinearity(middle) > linearity ? low : high) = middle;
  }
  return 0.5 * (low + high);
}

// Sets the biphasic stretch of `material` from KES tensile figures: the knee from the warp's EMT
// and LT, and each direction's stiffened slope so that its tension is 490 N/m at its EMT.
void setTensileTest(ClothMaterial& material, Real warpEmt, Real weftEmt, Real linearity) {
  const Real knee = kneeFromKes(material.warpStretchStiffness, warpEmt, linearity);
  material.stretchKneeStrain = knee;
  material.warpStiffenedStretchStiffness =
      stiffenedSlope(material.warpStretchStiffness, knee, warpEmt);
  material.weftStiffenedStretchStiffness =
      stiffenedSlope(material.weftStretchStiffness, knee, weftEmt);
}

// A material from its measured (or estimated) stiffnesses, damped like the curtain.
ClothMaterial makeFabric(Real arealDensity, Real warpStretch, Real weftStretch, Real shear,
                         Real bending, Real friction, Real thickness, Real strainLimit) {
  ClothMaterial material;
  material.arealDensity = arealDensity;
  material.warpStretchStiffness = warpStretch;
  material.weftStretchStiffness = weftStretch;
  material.shearStiffness = shear;
  material.bendingStiffness = bending;
  // Mean of warp and weft: Material.h has one stretch damping for both directions.
  material.stretchDamping = kStretchDampingTime * 0.5 * (warpStretch + weftStretch);
  material.shearDamping = kShearDampingTime * shear;
  material.bendingDamping = kBendingDampingTime * bending;
  material.friction = friction;
  material.thickness = thickness;
  material.strainLimit = strainLimit;
  return material;
}

constexpr std::array<std::string_view, 6> kNames{"cotton", "wool",  "polyester",
                                                 "silk",   "denim", "linen"};

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (std::tolower(static_cast<unsigned char>(a[k])) !=
        std::tolower(static_cast<unsigned char>(b[k]))) {
      return false;
    }
  }
  return true;
}

}  // namespace

ClothMaterial cottonFabric() {
  // The curtain's material: the defaults plus a strain limit (a test checks it).
  // In KES terms: 0.15 kg/m² is a 150 g/m² shirting; D = 2.3e-6 N·m is B ≈ 0.023 gf·cm²/cm (a
  // light lawn; shirting is 0.05–0.1) [KES]; 100 N/m shear is G ≈ 1.8 gf/(cm·deg) [KES];
  // 260 N/m stretch lies within [W11]'s low-strain slopes (2·C: 33 N/m for the cotton/polyester
  // interlock up to 2028 N/m for the denim weft). Strain limit 0.10: plain-woven cotton's
  // low-strain regime ends at about 10 % [EST, Provot 1995's threshold]; the defaults leave the
  // limiter off, the preset turns it on.
  ClothMaterial material;
  material.strainLimit = 0.10;
  return material;
}

ClothMaterial woolFabric() {
  return makeFabric(0.25,    // kg/m²: 250 g/m² worsted suiting [EST, catalogue weight]
                    180.0,   // N/m warp [EST]: wool crimp makes it softer in stretch than cotton
                    150.0,   // N/m weft [EST]
                    0.6 * kShearFromKes,      // G ≈ 0.6 gf/(cm·deg) → 34 N/m [KES, suiting]
                    0.10 * kBendingFromKes,   // B ≈ 0.10 gf·cm²/cm → 9.8e-6 N·m [KES, suiting]
                    0.35,    // [EST]
                    0.004,   // m [EST]
                    0.15);   // strain [EST]: crimped wool yarns straighten before they extend
}

ClothMaterial polyesterFabric() {
  return makeFabric(0.113,   // kg/m² [W11 "tango-red-jet-set", 100 % polyester jacket]
                    86.0,    // N/m warp = 2 × 43.1 [W11, first stretch sample]
                    343.0,   // N/m weft = 2 × 171.4 [W11, first stretch sample]
                    0.6 * kShearFromKes,      // G ≈ 0.6 gf/(cm·deg) → 34 N/m [KES, polyester]
                    0.05 * kBendingFromKes,   // B ≈ 0.05 gf·cm²/cm → 4.9e-6 N·m [KES, polyester]
                    0.25,    // [EST]
                    0.003,   // m [EST]
                    0.10);   // strain [EST]: a plain weave, like cotton
}

ClothMaterial silkFabric() {
  return makeFabric(0.06,    // kg/m²: 60 g/m² habutai / crêpe de Chine [EST, catalogue weight]
                    200.0,   // N/m warp [EST]
                    200.0,   // N/m weft [EST]
                    0.4 * kShearFromKes,      // G ≈ 0.4 gf/(cm·deg) → 22 N/m [KES, silk]
                    0.015 * kBendingFromKes,  // B ≈ 0.015 gf·cm²/cm → 1.5e-6 N·m [KES, silk]
                    0.2,     // [EST]
                    0.002,   // m [EST]
                    0.10);   // strain [EST]: a plain weave, like cotton
}

ClothMaterial denimFabric() {
  return makeFabric(0.324,   // kg/m² [W11 "11oz-black-denim", 99 % cotton]
                    411.0,   // N/m warp = 2 × 205.4 [W11, first stretch sample]
                    2028.0,  // N/m weft = 2 × 1013.9 [W11, first stretch sample]
                    2.0 * kShearFromKes,      // G ≈ 2.0 gf/(cm·deg) → 112 N/m [KES, denim 1.5–3.4]
                    0.17 * kBendingFromKes,   // B ≈ 0.17 gf·cm²/cm → 1.7e-5 N·m [KES, 0.14–0.23]
                    0.35,    // [EST]
                    0.004,   // m [EST]
                    0.06);   // strain [EST]: a dense twill of heavy yarns, little crimp to give
}

ClothMaterial linenFabric() {
  return makeFabric(0.18,    // kg/m²: 180 g/m² dress linen [EST, catalogue weight]
                    400.0,   // N/m warp [EST]: flax yarns extend little
                    400.0,   // N/m weft [EST]
                    1.6 * kShearFromKes,      // G ≈ 1.6 gf/(cm·deg) → 90 N/m [KES, linen]
                    0.20 * kBendingFromKes,   // B ≈ 0.20 gf·cm²/cm → 2.0e-5 N·m [KES, linen]
                    0.35,    // [EST]
                    0.003,   // m [EST]
                    0.06);   // strain [EST]: flax fibres extend only a few per cent
}

std::span<const std::string_view> fabricPresetNames() { return kNames; }

Result<ClothMaterial> fabricPreset(std::string_view name) {
  using Maker = ClothMaterial (*)();
  constexpr std::array<Maker, kNames.size()> kMakers{cottonFabric, woolFabric,  polyesterFabric,
                                                     silkFabric,   denimFabric, linenFabric};
  for (std::size_t k = 0; k < kNames.size(); ++k) {
    if (equalsIgnoringCase(name, kNames[k])) return kMakers[k]();
  }
  std::string valid;
  for (std::string_view known : kNames) {
    if (!valid.empty()) valid += ", ";
    valid += known;
  }
  return Error{"fabric preset '" + std::string(name) + "' is unknown; choose one of: " + valid};
}

Result<ClothMaterial> stiffeningFabricPreset(std::string_view name) {
  // Tensile figures [KES-T]: EMT of warp and weft and the linearity LT. LT 0.65 for all, the
  // middle of woven apparel fabrics' 0.55–0.75.
  struct TensileTest {
    std::string_view name;
    Real warpEmt, weftEmt, linearity;
  };
  constexpr std::array<TensileTest, kNames.size()> kTests{{
      {"cotton", 0.05, 0.05, 0.65},     // shirting, EMT 3–6 %
      {"wool", 0.06, 0.07, 0.65},       // worsted suiting, 4–8 %
      {"polyester", 0.04, 0.04, 0.65},  // polyester wovens, 2–5 %
      {"silk", 0.07, 0.07, 0.65},       // habutai and crêpe, 4–10 %
      {"denim", 0.03, 0.05, 0.65},      // denim, 2–5 %, the warp stiffer
      {"linen", 0.03, 0.03, 0.65},      // linen, 2–4 %
  }};
  Result<ClothMaterial> preset = fabricPreset(name);
  if (!preset.ok()) return preset;
  ClothMaterial material = preset.value();
  for (const TensileTest& test : kTests) {
    if (!equalsIgnoringCase(name, test.name)) continue;
    setTensileTest(material, test.warpEmt, test.weftEmt, test.linearity);
    material.strainLimit = std::max(test.warpEmt, test.weftEmt);
  }
  return material;
}

}  // namespace weft
