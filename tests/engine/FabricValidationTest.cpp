// The fabric presets in the two standard drape measurements (scenes/Cantilever.h, CusickDrape.h):
// the ASTM D1388 cantilever against the exact heavy elastica of the preset's own rigidity, and the
// Cusick drape test on an irregular disc mesh: settled within a few seconds, the same on two
// different meshes, and ordered by bending length as Cusick's measurements are. Measured figures:
// bench/results/fabric-validation.md.
#include "KnownEngineFailure.h"

#include <weft/scenes/Cantilever.h>
#include <weft/scenes/CusickDrape.h>

#include <weft/engine/FabricPresets.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace weft {
namespace {

class FabricPreset : public ::testing::TestWithParam<std::string> {};

// D1388's bending length of a strip of rigidity D (N·m) and areal density ρ (kg/m²): half the
// overhang at which the exact elastica's chord hangs 41.5° (Peirce: (D / ρ g)^(1/3)).
Real elasticaBendingLength(const ClothMaterial& material) {
  const Real load = CantileverScene::elasticaLoad(CantileverScene::kTestAngle);
  return 0.5 * std::cbrt(load * material.bendingStiffness / (material.arealDensity * 9.81));
}

TEST_P(FabricPreset, CantileverBendingLengthIsTheElasticaOfItsRigidity) {
  // The strip converges to the continuum at first order in the mesh spacing (the clamped root's
  // stencil): 8 and 16 segments along the overhang, extrapolated (2 c₁₆ − c₈), must give the
  // elastica's bending length within 2 % (the O(Δ²) rest is (1/16)² ≈ 0.4 %; the strip is read
  // still to 0.1 mm/s). The solve is converged (residual 1e-8), so the shape is the material's.
  const ClothMaterial material = fabricPreset(GetParam()).value();
  CantileverSettings settings;
  settings.material = material;
  settings.solver.cgTolerance = 1e-8;
  settings.solver.cgStopping = PcgStopping::RelativeResidual;
  settings.solver.tightCgTolerance = 0;
  settings.solver.cgMaxIterations = 5000;
  settings.overhangSegments = 8;
  const Real coarse = CantileverScene::bendingLength(settings);
  settings.overhangSegments = 16;
  const Real fine = CantileverScene::bendingLength(settings);
  ASSERT_TRUE(std::isfinite(coarse) && std::isfinite(fine));
  const Real theory = elasticaBendingLength(material);
  RecordProperty("bending_length_cm", std::to_string(100 * fine));
  EXPECT_NEAR(2 * fine - coarse, theory, 0.02 * theory)
      << GetParam() << ": 8 segments " << 100 * coarse << " cm, 16 segments " << 100 * fine
      << " cm, elastica " << 100 * theory << " cm";
}

// The Cusick test of a preset on the default mesh for `seconds`, with the drape coefficient at
// the end and half a second before, and the hem's speed at the end.
struct DrapeResult {
  Real coefficient = 0, coefficientBefore = 0, hemSpeed = 0;
};

DrapeResult drape(const std::string& name, Real spacing, std::uint32_t seed, Real seconds) {
  CusickDrapeSettings settings;
  settings.material = fabricPreset(name).value();
  settings.spacing = spacing;
  settings.seed = seed;
  CusickDrapeScene scene = CusickDrapeScene::create(settings).value();
  const int frames = int(std::lround(seconds / CusickDrapeScene::kFrameDt));
  DrapeResult result;
  for (int frame = 1; frame <= frames; ++frame) {
    const StepStatus status = scene.stepFrame();
    EXPECT_FALSE(hasFlag(status, StepStatus::RolledBack) || hasFlag(status, StepStatus::Unstable))
        << name << " frame " << frame;
    if (frame == frames - 30) result.coefficientBefore = scene.drapeCoefficient();
  }
  result.coefficient = scene.drapeCoefficient();
  result.hemSpeed = scene.hemSpeed();
  return result;
}

TEST_P(FabricPreset, CusickDrapeSettlesWithinThreeSeconds) {
  // Released flat with the engine's defaults, the hem stops creeping: by 3 s it moves slower than
  // 2 mm/s and the drape coefficient changes by less than 0.005 over the last half second (the
  // drapemeter's own reading error is about ±0.02). A drape coefficient lies in (0, 1).
  const DrapeResult result = drape(GetParam(), 0.0075, 1, 3.0);
  RecordProperty("drape_coefficient", std::to_string(result.coefficient));
  EXPECT_NEAR(result.coefficient, result.coefficientBefore, 0.005) << GetParam();
  EXPECT_GT(result.coefficient, 0) << GetParam();
  EXPECT_LT(result.coefficient, 1) << GetParam();
  EXPECT_LT(result.hemSpeed, 0.002) << GetParam() << ": hem speed " << 1000 * result.hemSpeed
                                     << " mm/s at 3 s";
}

TEST(Cantilever, DenimBendsWithinItsPublishedBendingLength) {
  // The denim preset's source (FabricPresets.cpp, [KES]: Hindawi J. Textiles 2016, 4614168)
  // measured B = 0.14–0.23 gf·cm²/cm on denims; at its 324 g/m² [W11] that is a bending length
  // (B / W)^(1/3) of 1.63–1.92 cm. The strip's D1388 reading must fall in it.
  const Real weight = 0.0324;  // gf/cm²
  const Real lowest = std::cbrt(0.14 / weight) / 100, highest = std::cbrt(0.23 / weight) / 100;  // m
  CantileverSettings settings;
  settings.material = denimFabric();
  settings.overhangSegments = 16;
  const Real measured = CantileverScene::bendingLength(settings);
  RecordProperty("bending_length_cm", std::to_string(100 * measured));
  // The search brackets 41.5° by doubling the overhang, and the 4 cm strip it tries does not
  // come to rest at the default tolerance (ALongDenimStripComesToRestAtTheDefaultSolverTolerance):
  // where its flailing happens to stop moves the reading to either side of the range.
  char reading[32];
  std::snprintf(reading, sizeof reading, "%.2f cm", 100 * measured);
  test::knownEngineFailure(measured >= lowest && measured <= highest,
                           "denim's D1388 bending length within 1.63–1.92 cm",
                           std::string(reading) +
                               ": the bracket's 4 cm strip flails instead of resting at 55°, so "
                               "the interpolation starts from a wrong angle (converged: 1.66 cm)");
}

TEST(CusickDrape, TheDrapeCoefficientRisesWithTheBendingLength) {
  // Cusick (J. Textile Inst. 56, 1965): the drape coefficient grows with the bending length. The
  // presets, ordered by (D / ρ g)^(1/3), must drape in the same order on a 1 cm mesh (the mesh
  // moves a coefficient by ~0.01; silk and wool lie closer than that, so their order is the
  // fragile one). Every coefficient lies in (0, 1).
  std::vector<std::pair<Real, std::string>> byLength;
  for (std::string_view name : fabricPresetNames()) {
    const ClothMaterial m = fabricPreset(name).value();
    byLength.push_back({std::cbrt(m.bendingStiffness / (m.arealDensity * 9.81)), std::string(name)});
  }
  std::sort(byLength.begin(), byLength.end());
  Real previous = 0;
  std::string figures;
  for (const auto& [length, name] : byLength) {
    const Real coefficient = drape(name, 0.01, 3, 2.5).coefficient;
    EXPECT_GT(coefficient, 0) << name;
    EXPECT_LT(coefficient, 1) << name;
    EXPECT_GT(coefficient, previous) << name << " (bending length " << 100 * length << " cm)";
    figures += name + " " + std::to_string(100 * length).substr(0, 4) + " cm: " +
               std::to_string(coefficient).substr(0, 5) + "; ";
    previous = coefficient;
  }
  RecordProperty("drape_coefficients", figures);
}

INSTANTIATE_TEST_SUITE_P(Presets, FabricPreset,
                         ::testing::Values("cotton", "wool", "polyester", "silk", "denim", "linen"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

TEST(CusickDrape, TwoDifferentMeshesOfTheSameDiscAgree) {
  // Another seed and a 20 % finer spacing: another irregular mesh of the same specimen. Its drape
  // coefficient within 0.05 (the spread of repeated drapemeter readings of one fabric).
  const DrapeResult coarse = drape("cotton", 0.0075, 1, 3.0);
  const DrapeResult fine = drape("cotton", 0.006, 2, 3.0);
  EXPECT_NEAR(coarse.coefficient, fine.coefficient, 0.05);
}

TEST(CusickDrape, TheDiscMeshIsIrregularAndExactAtTheClampAndTheHem) {
  CusickDrapeSettings settings;
  const TriangleMesh mesh = cusickDiscMesh(settings).value();
  const Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok());
  // Not a grid: vertex valences spread (a regular grid's interior is all 6).
  std::vector<int> valence(mesh.positions.size(), 0);
  for (const Edge& edge : model.value().edges()) {
    ++valence[edge.vertices[0]];
    ++valence[edge.vertices[1]];
  }
  int notSix = 0;
  Real area = 0;
  for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
    const Vec3& a = mesh.positions[mesh.indices[t]];
    area += 0.5 * (mesh.positions[mesh.indices[t + 1]] - a)
                      .cross(mesh.positions[mesh.indices[t + 2]] - a)
                      .norm();
  }
  for (int v : valence) notSix += v != 6;
  EXPECT_GT(notSix, int(mesh.positions.size()) / 5);
  // The hem and the clamp are circles: the area is the disc's to the polygon's deficit.
  EXPECT_NEAR(area, 3.14159265358979 * 0.15 * 0.15, 0.002 * 3.14159265358979 * 0.15 * 0.15);
  int onClamp = 0;
  for (const Vec3& p : mesh.positions) onClamp += std::abs(std::hypot(p.x(), p.z()) - 0.09) < 1e-12;
  EXPECT_GT(onClamp, 60);
}

TEST(Cantilever, ALongDenimStripComesToRestAtTheDefaultSolverTolerance) {
  // A 4 cm denim strip of 2.5 mm cells (stiff stretch on 2 mg vertices) bends to about 55° and
  // stays there: over the last 5 of 10 s every vertex is slower than 1 mm/s, the strain stays
  // under 1 %, and the rest angle is a converged solve's (residual 1e-8) within 0.1°.
  CantileverSettings settings;
  settings.material = denimFabric();
  settings.overhangSegments = 16;
  settings.overhang = 0.04;
  struct Settled {
    Real angle = 0, fastest = 0, strain = 0;
  };
  const auto settle = [](const CantileverSettings& at) {
    CantileverScene scene = CantileverScene::create(at).value();
    Settled result;
    for (int frame = 0; frame < 600; ++frame) {
      scene.stepFrame();
      if (frame >= 300) {  // the last 5 s
        result.fastest = std::max(result.fastest, scene.largestSpeed());
        result.strain = std::max(result.strain, scene.world().stats().maxStrain);
      }
    }
    result.angle = scene.chordAngle() * 180 / std::numbers::pi;
    return result;
  };
  CantileverSettings converged = settings;
  converged.solver.cgTolerance = 1e-8;
  converged.solver.cgStopping = PcgStopping::RelativeResidual;
  converged.solver.tightCgTolerance = 0;
  converged.solver.cgMaxIterations = 5000;
  const Settled reference = settle(converged);
  ASSERT_LT(reference.fastest, 1e-3) << "the converged solve must come to rest";
  const Settled loose = settle(settings);
  RecordProperty("angle_degrees", std::to_string(loose.angle));
  const bool rests = loose.fastest < 1e-3 && loose.strain < 0.01 &&
                     std::abs(loose.angle - reference.angle) < 0.1;
  test::knownEngineFailure(
      rests, "a 4 cm denim strip at the default PCG tolerance comes to rest",
      "it flails for the whole 10 s (up to 1.9 m/s, strain at the 6 % limit; converged: 55.08°). "
      "A cold PCG start, or the warm start (the last step's Δv) scaled by its energy-best factor "
      "in [0, 1], brings it to rest at 55.08°: at the loose tolerance the raw warm start carries "
      "part of one step's Δv into the next. Either fix moves the chaotic wool drape and three "
      "dragged-pins draws past their bounds, so neither has landed");
}

}  // namespace
}  // namespace weft
