// saveState() / restoreState(): a restored world continues bit for bit like the original, and a
// restore that cannot apply changes nothing.
#include <weft/scenes/Curtain.h>

#include <gtest/gtest.h>

#include <vector>

namespace weft {
namespace {

class SaveStateIntegrator : public ::testing::TestWithParam<IntegratorKind> {};

TEST_P(SaveStateIntegrator, RestoredWorldContinuesBitForBit) {
  // BDF2 carries its history (the previous state and step) besides the warm start.
  CurtainSettings settings;
  settings.solver.integrator = GetParam();
  CurtainScene scene = CurtainScene::create(settings).value();
  for (int frame = 0; frame < 80; ++frame) scene.stepFrame();  // into the sphere push
  const WorldState saved = scene.world().saveState();
  const std::uint64_t savedHash = scene.world().stateHash();
  const Index savedFrame = scene.frame();

  std::vector<std::uint64_t> original;
  for (int frame = 0; frame < 40; ++frame) {
    scene.stepFrame();
    original.push_back(scene.world().stateHash());
  }
  ASSERT_NE(original.back(), savedHash);

  ASSERT_TRUE(scene.world().restoreState(saved).ok());
  EXPECT_EQ(scene.world().stateHash(), savedHash);
  scene.rewindTo(savedFrame);
  for (int frame = 0; frame < 40; ++frame) {
    scene.stepFrame();
    ASSERT_EQ(scene.world().stateHash(), original[frame]) << "frame " << frame;
  }
}

INSTANTIATE_TEST_SUITE_P(Implicit, SaveStateIntegrator,
                         ::testing::Values(IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2),
                         [](const ::testing::TestParamInfo<IntegratorKind>& info) {
                           return info.param == IntegratorKind::Bdf2 ? "Bdf2" : "ImplicitEuler";
                         });

TEST(SaveState, RestoreWithAMissingClothChangesNothing) {
  World world;
  GridSettings grid;
  grid.columns = grid.rows = 5;
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  const ClothId first = world.createCloth(model, ClothSettings{}).value();
  const ClothId second = world.createCloth(model, ClothSettings{}).value();
  const WorldState saved = world.saveState();
  world.step(1.0 / 60.0);
  ASSERT_TRUE(world.destroyCloth(first).ok());
  const std::uint64_t hash = world.stateHash();
  const Status restored = world.restoreState(saved);
  ASSERT_FALSE(restored.ok());
  EXPECT_NE(restored.error().message.find("destroyed cloth"), std::string::npos);
  EXPECT_EQ(world.stateHash(), hash);
  EXPECT_TRUE(world.positions(second).ok());
}

}  // namespace
}  // namespace weft
