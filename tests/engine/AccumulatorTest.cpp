// FixedStepAccumulator: a fixed number of steps per second of display time, whatever the display
// rate; a cap after stalls; and a world stepped through it ends in the same state at any rate.
#include <weft/engine/FixedStepAccumulator.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace weft {
namespace {

TEST(FixedStepAccumulator, StepsFollowDisplayTimeNotDisplayRate) {
  for (Real hertz : {30.0, 40.0, 60.0, 75.0, 144.0, 240.0}) {
    FixedStepAccumulator accumulator(1.0 / 60);
    std::uint64_t steps = 0;
    const int frames = int(std::lround(hertz * 3));  // 3 s of display
    for (int frame = 0; frame < frames; ++frame) {
      const int taken = accumulator.advance(1.0 / hertz);
      EXPECT_GE(taken, 0);
      EXPECT_LE(taken, 4);
      steps += std::uint64_t(taken);
      EXPECT_GE(accumulator.alpha(), 0.0);
      EXPECT_LT(accumulator.alpha(), 1.0);
    }
    EXPECT_EQ(steps, 180u) << hertz << " Hz";
    EXPECT_EQ(accumulator.totalSteps(), steps);
  }
}

TEST(FixedStepAccumulator, AFrameOfExactlyOneStepTakesOneStep) {
  FixedStepAccumulator accumulator(1.0 / 60);
  for (int frame = 0; frame < 1000; ++frame) ASSERT_EQ(accumulator.advance(1.0 / 60), 1);
}

TEST(FixedStepAccumulator, AStallIsCappedAndBadTimesAddNothing) {
  FixedStepAccumulator accumulator(0.01, 3);
  EXPECT_EQ(accumulator.advance(1.0), 3);
  EXPECT_EQ(accumulator.droppedSteps(), 97u);
  EXPECT_NEAR(accumulator.alpha(), 0.0, 1e-9);
  for (Real bad : {-1.0, 0.0, std::numeric_limits<Real>::quiet_NaN(),
                   std::numeric_limits<Real>::infinity()}) {
    EXPECT_EQ(accumulator.advance(bad), 0);
  }
  EXPECT_EQ(accumulator.totalSteps(), 3u);
  EXPECT_EQ(accumulator.advance(0.015), 1);
  EXPECT_NEAR(accumulator.alpha(), 0.5, 1e-9);
  FixedStepAccumulator invalid(-1, 0);  // falls back to 1/60 s and one step per frame
  EXPECT_DOUBLE_EQ(invalid.step(), 1.0 / 60);
  EXPECT_EQ(invalid.advance(1.0), 1);
}

TEST(FixedStepAccumulator, AWorldEndsInTheSameStateAtAnyDisplayRate) {
  GridSettings grid;
  grid.columns = 7;
  grid.rows = 5;
  grid.width = 0.3;
  grid.height = 0.2;
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  for (Index c = 0; c < grid.columns; ++c) settings.pinnedVertices.push_back((grid.rows - 1) * grid.columns + c);
  std::uint64_t reference = 0;
  for (Real hertz : {40.0, 60.0, 144.0}) {
    World world;
    (void)world.createCloth(model, settings).value();
    FixedStepAccumulator accumulator;
    const int frames = int(std::lround(hertz));  // 1 s of display
    for (int frame = 0; frame < frames; ++frame) {
      for (int k = accumulator.advance(1.0 / hertz); k > 0; --k) world.step(accumulator.step());
    }
    EXPECT_EQ(accumulator.totalSteps(), 60u);
    if (reference == 0) reference = world.stateHash();
    EXPECT_EQ(world.stateHash(), reference) << hertz << " Hz";
  }
}

}  // namespace
}  // namespace weft
