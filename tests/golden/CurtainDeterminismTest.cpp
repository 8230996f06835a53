// Determinism contract (docs/architecture.md, "Threads and determinism"): the same inputs and binary give bitwise-identical
// positions and velocities for 1, 2 and 8 threads, every frame, every run.
//
// The curtain runs its whole script (600 frames: the settle, the sphere's push and withdrawal,
// the gather into folds, the hold and the opening) on 1, 2 and 8 threads; the state hash after
// every frame of each run must equal the 1-thread run's, and each run's final state is its golden
// hash ("curtain/600-frames/<n>-threads", tests/golden/state-hashes.json).
#include "golden/GoldenHashes.h"

#include <weft/scenes/Curtain.h>

#include <oneapi/tbb/global_control.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace weft {
namespace {

std::vector<std::uint64_t> curtainHashes(int threads, Index frames) {
  TaskSystem tasks(TaskSystemSettings{threads});
  CurtainSettings settings;
  settings.taskSystem = &tasks;
  Result<CurtainScene> created = CurtainScene::create(settings);
  EXPECT_TRUE(created.ok());
  CurtainScene& scene = created.value();
  std::vector<std::uint64_t> hashes;
  hashes.reserve(frames);
  for (Index frame = 0; frame < frames; ++frame) {
    scene.stepFrame();
    hashes.push_back(scene.world().stateHash());
  }
  EXPECT_EQ(scene.world().threadCount(), threads);
  return hashes;
}

TEST(Determinism, TheWholeCurtainIsBitwiseIdenticalOnOneTwoAndEightThreadsAndMatchesItsGoldenHash) {
  // Let oneTBB run 8 real threads on a machine with fewer cores, so 8 means 8.
  tbb::global_control allowEight(tbb::global_control::max_allowed_parallelism, 8);
  constexpr Index kFrames = CurtainScene::kFrames;
  std::vector<std::uint64_t> reference;
  for (int threads : {1, 2, 8}) {
    const std::vector<std::uint64_t> hashes = curtainHashes(threads, kFrames);
    ASSERT_EQ(hashes.size(), std::size_t(kFrames));
    test::expectGoldenHash("curtain/600-frames/" + std::to_string(threads) +
                               (threads == 1 ? "-thread" : "-threads"),
                           hashes.back());
    if (threads == 1) {
      reference = hashes;
      continue;
    }
    for (Index frame = 0; frame < kFrames; ++frame) {
      if (hashes[frame] != reference[frame]) {
        ADD_FAILURE() << threads << " threads: the state first differs from the 1-thread run's "
                      << "after frame " << frame + 1 << " (" << test::formatHash(hashes[frame])
                      << " against " << test::formatHash(reference[frame]) << ")";
        break;
      }
    }
  }
  // The hash moves: a frozen cloth would pass the comparison trivially.
  EXPECT_NE(reference.front(), reference.back());
}

}  // namespace
}  // namespace weft
