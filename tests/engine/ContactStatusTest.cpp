// The step's status says when the contact projection stops at its sweep cap with contacts still
// closer than their thickness (StepStatus::ContactsUnresolved, StepStats::unresolvedContacts):
// a pin yanked across a hanging sheet folds its top edge onto itself, and that frame's
// projection runs out of sweeps; the calm frames before it never are flagged. Nothing crosses
// either way: the impact pass has the last word.
#include "ContactTestSupport.h"

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace weft {
namespace {

TEST(ContactStatus, AYankedPinsUnresolvedContactsAreFlaggedAndTheCalmFramesAreNot) {
  // A 1 m cotton sheet of 21 × 21 vertices hangs from its two top corners for 60 frames; then
  // one corner's target moves 0.5 m towards the other in one frame (weft-pin-yank's scene,
  // smaller).
  constexpr Index kSide = 21;
  GridSettings grid;
  grid.columns = grid.rows = kSide;
  grid.width = grid.height = 1.0;
  grid.origin = Vec3(-0.5, 1.5, 0);
  const auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  settings.material = cottonFabric();
  settings.pinnedVertices = {(kSide - 1) * kSide, kSide * kSide - 1};
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  World world(worldSettings);
  const ClothId cloth = world.createCloth(model, settings).value();
  test::IntersectionCounter counter(world, {cloth});
  for (int frame = 0; frame < 60; ++frame) {
    const StepStatus status = world.step(1.0 / 60.0);
    ASSERT_FALSE(hasFlag(status, StepStatus::ContactsUnresolved))
        << "frame " << frame << ": " << describe(status);
    ASSERT_EQ(world.stats().unresolvedContacts, 0u) << "frame " << frame;
  }
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  targets[0].x() += 0.5;
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
  const StepStatus yank = world.step(1.0 / 60.0);
  EXPECT_TRUE(hasFlag(yank, StepStatus::ContactsUnresolved)) << describe(yank);
  EXPECT_NE(describe(yank).find("contacts-unresolved"), std::string::npos) << describe(yank);
  EXPECT_GT(world.stats().unresolvedContacts, 0u);
  EXPECT_EQ(counter.count(world), 0u) << "the yanked sheet crosses itself";
}

}  // namespace
}  // namespace weft
