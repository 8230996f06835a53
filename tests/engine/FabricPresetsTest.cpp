// Fabric presets: cotton is the curtain material, every preset is a valid material, lookup by
// name works and a bad name is told what the good ones are.
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>

namespace weft {
namespace {

using ::testing::HasSubstr;

TEST(FabricPresets, CottonIsTheCurtainMaterial) {
  // docs/curtain-benchmark.md: the curtain's default material is "cotton". Compared field by field, exactly.
  const ClothMaterial cotton = cottonFabric();
  const ClothMaterial defaults{};
  EXPECT_EQ(cotton.arealDensity, 0.15);
  EXPECT_EQ(cotton.warpStretchStiffness, 260.0);
  EXPECT_EQ(cotton.weftStretchStiffness, 260.0);
  EXPECT_EQ(cotton.shearStiffness, 100.0);
  EXPECT_EQ(cotton.bendingStiffness, 2.3e-6);
  EXPECT_EQ(cotton.arealDensity, defaults.arealDensity);
  EXPECT_EQ(cotton.warpStretchStiffness, defaults.warpStretchStiffness);
  EXPECT_EQ(cotton.weftStretchStiffness, defaults.weftStretchStiffness);
  EXPECT_EQ(cotton.shearStiffness, defaults.shearStiffness);
  EXPECT_EQ(cotton.bendingStiffness, defaults.bendingStiffness);
  EXPECT_EQ(cotton.warpRestScale, defaults.warpRestScale);
  EXPECT_EQ(cotton.weftRestScale, defaults.weftRestScale);
  EXPECT_EQ(cotton.stretchDamping, defaults.stretchDamping);
  EXPECT_EQ(cotton.shearDamping, defaults.shearDamping);
  EXPECT_EQ(cotton.bendingDamping, defaults.bendingDamping);
  EXPECT_EQ(cotton.airDrag, defaults.airDrag);
  EXPECT_EQ(cotton.thickness, defaults.thickness);
  EXPECT_EQ(cotton.friction, defaults.friction);
  // The limiter is opt-in (ClothMaterial::strainLimit): the preset turns it on.
  EXPECT_EQ(defaults.strainLimit, 0.0);
  EXPECT_EQ(cotton.strainLimit, 0.10);
}

TEST(FabricPresets, EveryNameGivesAMaterialTheWorldAccepts) {
  GridSettings grid;
  grid.columns = 5;
  grid.rows = 4;
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ASSERT_EQ(fabricPresetNames().size(), 6u);
  for (std::string_view name : fabricPresetNames()) {
    const Result<ClothMaterial> material = fabricPreset(name);
    ASSERT_TRUE(material.ok()) << name;
    // Physically ordered where the sources agree: everything positive, damping ≈ 2 ms Rayleigh.
    const ClothMaterial& m = material.value();
    EXPECT_GT(m.arealDensity, 0.03) << name;
    EXPECT_LT(m.arealDensity, 0.5) << name;
    EXPECT_GT(m.bendingStiffness, 0) << name;
    EXPECT_GT(m.shearStiffness, 0) << name;
    EXPECT_NEAR(m.shearDamping / m.shearStiffness, 0.002, 1e-9) << name;
    EXPECT_GE(m.strainLimit, 0.03) << name;  // woven fabric: a few to ~15 % (FabricPresets.cpp)
    EXPECT_LE(m.strainLimit, 0.15) << name;
    World world;
    ClothSettings settings;
    settings.material = m;
    EXPECT_TRUE(world.createCloth(model, settings).ok()) << name;
  }
  // Denim is the heaviest and stiffest in bending, silk the lightest and limpest.
  EXPECT_GT(denimFabric().arealDensity, woolFabric().arealDensity);
  EXPECT_LT(silkFabric().arealDensity, cottonFabric().arealDensity);
  EXPECT_GT(denimFabric().bendingStiffness, cottonFabric().bendingStiffness);
  EXPECT_LT(silkFabric().bendingStiffness, cottonFabric().bendingStiffness);
}

TEST(FabricPresets, LookupIsCaseInsensitiveAndTheErrorListsValidNames) {
  EXPECT_EQ(fabricPreset("Denim").value().arealDensity, denimFabric().arealDensity);
  EXPECT_EQ(fabricPreset("COTTON").value().bendingStiffness, ClothMaterial{}.bendingStiffness);
  const Result<ClothMaterial> unknown = fabricPreset("tweed");
  ASSERT_FALSE(unknown.ok());
  EXPECT_THAT(unknown.error().message, HasSubstr("'tweed'"));
  for (std::string_view name : fabricPresetNames()) {
    EXPECT_THAT(unknown.error().message, HasSubstr(std::string(name)));
  }
  EXPECT_FALSE(fabricPreset("").ok());
}

}  // namespace
}  // namespace weft
