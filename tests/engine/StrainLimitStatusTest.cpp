// The step's status says when a cloth ends a frame past its strain limit
// (StepStatus::StrainLimitExceeded, StepStats::clothsOverStrainLimit): pins pulled apart beyond
// what the limit allows are flagged in every frame, a sheet hanging within its limit never is,
// and a cloth without a limit has none to exceed. A frame that ends past the limit is redone
// with more substeps when that can help: not while the pins hold the cloth past it.
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <string>

namespace weft {
namespace {

constexpr Real kFrame = 1.0 / 60.0;
constexpr Index kColumns = 11, kRows = 5;
constexpr Real kWidth = 0.5;  // m

std::shared_ptr<const ClothModel> strip() {
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = kWidth;
  grid.height = 0.2;
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

// Both short sides of the strip pinned; `strainLimit` on cotton.
ClothSettings pinnedAtBothEnds(Real strainLimit) {
  ClothSettings settings;
  settings.material = cottonFabric();
  settings.material.strainLimit = strainLimit;
  for (Index r = 0; r < kRows; ++r) {
    settings.pinnedVertices.push_back(r * kColumns);
    settings.pinnedVertices.push_back(r * kColumns + kColumns - 1);
  }
  return settings;
}

// Moves the pins of the strip's right side by `shift` along its length.
void pullRightSide(World& world, ClothId cloth, const ClothSettings& settings, Real shift) {
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (std::size_t k = 0; k < targets.size(); ++k) {
    if (settings.pinnedVertices[k] % kColumns == kColumns - 1) targets[k].x() += shift;
  }
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
}

// The strip with `settings` (pinnedAtBothEnds) in `world`, its right pins pulled by `pull` times
// its width.
void addPulledStrip(World& world, const ClothSettings& settings, Real pull) {
  const ClothId cloth = world.createCloth(strip(), settings).value();
  pullRightSide(world, cloth, settings, pull * kWidth);
}

TEST(StrainLimitStatus, PinsPulledApartPastTheLimitAreFlaggedInEveryFrame) {
  // The pins 1.3 times the strip's length apart: every edge along it must stretch 0.3, three
  // times the limit of 0.10.
  World world;
  addPulledStrip(world, pinnedAtBothEnds(0.1), 0.3);
  for (int frame = 0; frame < 30; ++frame) {
    const StepStatus status = world.step(kFrame);
    ASSERT_GT(world.stats().maxStrain, 0.1 + kStrainLimitSlack) << "frame " << frame;
    EXPECT_TRUE(hasFlag(status, StepStatus::StrainLimitExceeded)) << "frame " << frame;
    EXPECT_EQ(world.stats().clothsOverStrainLimit, 1u) << "frame " << frame;
    EXPECT_NE(describe(status).find("strain-limit-exceeded"), std::string::npos);
  }
}

TEST(StrainLimitStatus, ASheetWithinItsLimitIsNeverFlagged) {
  // The same strip pulled by 5 %, within the limit: the limit is met, nothing is reported.
  World world;
  addPulledStrip(world, pinnedAtBothEnds(0.1), 0.05);
  for (int frame = 0; frame < 60; ++frame) {
    const StepStatus status = world.step(kFrame);
    EXPECT_LE(world.stats().maxStrain, 0.1 + kStrainLimitSlack) << "frame " << frame;
    EXPECT_FALSE(hasFlag(status, StepStatus::StrainLimitExceeded)) << "frame " << frame;
    EXPECT_EQ(world.stats().clothsOverStrainLimit, 0u) << "frame " << frame;
  }
}

TEST(StrainLimitStatus, AClothWithoutALimitHasNoneToExceed) {
  World world;
  addPulledStrip(world, pinnedAtBothEnds(0), 0.3);
  for (int frame = 0; frame < 10; ++frame) {
    const StepStatus status = world.step(kFrame);
    EXPECT_GT(world.stats().maxStrain, 0.1 + kStrainLimitSlack) << "frame " << frame;
    EXPECT_FALSE(hasFlag(status, StepStatus::StrainLimitExceeded)) << "frame " << frame;
  }
}

TEST(StrainLimitStatus, AFramePastTheLimitIsRedoneWithTwiceTheSubstepsUpToItsCap) {
  // Pins pulled 1.3 times the strip's length apart: no substep count can meet the limit. The
  // frame of the pull (three substeps for the pins' travel, maxPinTravelPerSubstep) is redone
  // with six (twice that, within strainRetrySubsteps = 8) and still flagged. The frames after it
  // start past the limit that the retries could not meet: they keep their one substep, flagged.
  // With the retries off no frame is redone.
  for (const Index cap : {Index(8), Index(0)}) {
    World world;
    ClothSettings settings = pinnedAtBothEnds(0.1);
    settings.solver.strainRetrySubsteps = cap;
    const ClothId cloth = world.createCloth(strip(), settings).value();
    pullRightSide(world, cloth, settings, 0.3 * kWidth);
    const StepStatus pulled = world.step(kFrame);
    EXPECT_TRUE(hasFlag(pulled, StepStatus::StrainLimitExceeded));
    EXPECT_EQ(world.stats().strainRetries, cap == 8 ? 1u : 0u);
    EXPECT_EQ(world.stats().substeps, cap == 8 ? 6u : 3u);
    for (int frame = 1; frame < 6; ++frame) {
      const StepStatus status = world.step(kFrame);
      EXPECT_TRUE(hasFlag(status, StepStatus::StrainLimitExceeded)) << "frame " << frame;
      EXPECT_EQ(world.stats().strainRetries, 0u) << "frame " << frame;
      EXPECT_EQ(world.stats().substeps, 1u) << "frame " << frame;
    }
  }
}

TEST(StrainLimitStatus, AClothBackWithinItsLimitIsRedoneAgainWhenPulledPastIt) {
  // Released to 5 % the strip ends within its limit; pulled past it again, from rest, with no
  // pin travel in the frame: that frame's excess is new, so it is redone with 2, 4 and 8 substeps.
  World world;
  const ClothSettings settings = pinnedAtBothEnds(0.1);
  const ClothId cloth = world.createCloth(strip(), settings).value();
  pullRightSide(world, cloth, settings, 0.3 * kWidth);
  for (int frame = 0; frame < 3; ++frame) (void)world.step(kFrame);
  pullRightSide(world, cloth, settings, -0.25 * kWidth);
  for (int frame = 0; frame < 30; ++frame) (void)world.step(kFrame);
  ASSERT_LE(world.stats().maxStrain, 0.1 + kStrainLimitSlack);
  pullRightSide(world, cloth, settings, 0.25 * kWidth);
  const StepStatus pulled = world.step(kFrame);
  EXPECT_TRUE(hasFlag(pulled, StepStatus::StrainLimitExceeded));
  EXPECT_GE(world.stats().strainRetries, 1u);
}

TEST(StrainLimitStatus, AFrameWithinTheLimitIsNotRedone) {
  World world;
  addPulledStrip(world, pinnedAtBothEnds(0.1), 0.05);
  for (int frame = 0; frame < 30; ++frame) {
    (void)world.step(kFrame);
    EXPECT_EQ(world.stats().strainRetries, 0u) << "frame " << frame;
    EXPECT_EQ(world.stats().substeps, 1u) << "frame " << frame;
  }
}

}  // namespace
}  // namespace weft
