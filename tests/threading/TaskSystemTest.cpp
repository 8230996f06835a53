// TaskSystem and PerWorker: coverage of every index, the fixed split, worker indices, ordered
// reductions that give the same bits on 1, 2 and 8 threads, scratch that is never shared, and
// thread ownership (caller's arena, serial mode on the caller's thread).
#include <weft/threading/GrainSizes.h>
#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <gtest/gtest.h>
#include <oneapi/tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

namespace weft {
namespace {

using Index = TaskSystem::Index;

/// oneTBB's pool defaults to the machine's cores (2 here); let 8-slot arenas get 8 real threads so
/// that the concurrency tests see real interleavings. The test, as the host, decides this.
class AllowThreads {
 public:
  explicit AllowThreads(int threads)
      : m_control(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads)) {}

 private:
  tbb::global_control m_control;
};

/// Written and never read, so the optimiser keeps the loops whose results land here.
thread_local volatile double t_sink = 0.0;

/// Burns a little CPU so that blocks overlap in time (no timing is asserted).
double busyWork(Index begin, Index end) {
  double x = 0.0;
  for (Index i = begin; i < end; ++i) {
    for (int k = 0; k < 200; ++k) x += std::sqrt(static_cast<double>(i + k));
  }
  t_sink = x;
  return x;
}

TEST(TaskSystem, BlockCountIsCountOverGrainRoundedUp) {
  EXPECT_EQ(TaskSystem::blockCount(0, 1), 0u);
  EXPECT_EQ(TaskSystem::blockCount(0, 64), 0u);
  EXPECT_EQ(TaskSystem::blockCount(1, 64), 1u);
  EXPECT_EQ(TaskSystem::blockCount(64, 64), 1u);
  EXPECT_EQ(TaskSystem::blockCount(65, 64), 2u);
  EXPECT_EQ(TaskSystem::blockCount(10, 3), 4u);
  EXPECT_EQ(TaskSystem::blockCount(9, 3), 3u);
  // No overflow near the top of the index range.
  EXPECT_EQ(TaskSystem::blockCount(0xFFFFFFFFu, 1), 0xFFFFFFFFu);
  EXPECT_EQ(TaskSystem::blockCount(0xFFFFFFFFu, 0x80000000u), 2u);
}

TEST(TaskSystem, DefaultThreadCountIsTheMachinesCores) {
  TaskSystem tasks;
  EXPECT_EQ(tasks.threadCount(), std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  EXPECT_EQ(tasks.isSerial(), tasks.threadCount() == 1);
}

TEST(TaskSystem, ParallelForVisitsEveryIndexExactlyOnce) {
  AllowThreads allow(8);
  for (int threads : {1, 2, 3, 8}) {
    TaskSystem tasks({.threadCount = threads});
    for (Index count : {0u, 1u, 7u, 64u, 1000u, 1023u, 4097u}) {
      for (Index grain : {1u, 3u, 64u, 1000u, 5000u}) {
        std::vector<std::atomic<int>> visits(count);
        tasks.parallelFor(count, grain, [&](Index begin, Index end, int) {
          for (Index i = begin; i < end; ++i) visits[i].fetch_add(1, std::memory_order_relaxed);
        });
        Index wrong = 0;
        for (Index i = 0; i < count; ++i) wrong += visits[i].load() != 1;
        EXPECT_EQ(wrong, 0u) << "threads " << threads << " count " << count << " grain " << grain;
      }
    }
  }
}

TEST(TaskSystem, BlocksAreExactlyTheFixedSplit) {
  AllowThreads allow(8);
  for (int threads : {1, 2, 8}) {
    TaskSystem tasks({.threadCount = threads});
    for (auto [count, grain] : std::vector<std::pair<Index, Index>>{{1000, 64}, {1024, 64}, {5, 1}, {3, 10}, {4097, 1000}, {0xFFFFFFF0u, 0x80000000u}}) {
      const Index blocks = TaskSystem::blockCount(count, grain);
      std::vector<std::pair<Index, Index>> seen(blocks, {~0u, ~0u});
      std::atomic<Index> calls{0};
      std::atomic<int> misaligned{0};
      tasks.parallelFor(count, grain, [&](Index begin, Index end, int) {
        calls.fetch_add(1);
        if (begin % grain != 0 || begin / grain >= blocks) {
          misaligned.fetch_add(1);
          return;
        }
        seen[begin / grain] = {begin, end};
      });
      EXPECT_EQ(calls.load(), blocks);
      EXPECT_EQ(misaligned.load(), 0);
      for (Index k = 0; k < blocks; ++k) {
        EXPECT_EQ(seen[k].first, k * grain) << "block " << k << " threads " << threads;
        // 64-bit arithmetic: the last block of a count near 2³² must not wrap.
        EXPECT_EQ(seen[k].second, std::min<std::uint64_t>(count, (std::uint64_t{k} + 1) * grain))
            << "block " << k << " threads " << threads;
      }
    }
  }
}

/// (thread, workerIndex) of every block of one parallelFor of `count` single-element blocks.
std::vector<std::pair<std::thread::id, int>> recordWorkers(TaskSystem& tasks, Index count) {
  std::vector<std::pair<std::thread::id, int>> workerOfBlock(count, {std::thread::id(), -1});
  tasks.parallelFor(count, 1, [&](Index begin, Index, int worker) {
    workerOfBlock[begin] = {std::this_thread::get_id(), worker};
    busyWork(0, 20);
  });
  return workerOfBlock;
}

TEST(TaskSystem, WorkerIndicesAreInRangeAndTheCallerHoldsZero) {
  const std::thread::id caller = std::this_thread::get_id();
  for (int threads : {2, 4, 8}) {
    AllowThreads allow(threads);
    TaskSystem tasks({.threadCount = threads});
    for (int repeat = 0; repeat < 20; ++repeat) {
      for (const auto& [thread, worker] : recordWorkers(tasks, 256)) {
        ASSERT_GE(worker, 0);
        ASSERT_LT(worker, threads);
        // Slot 0 is reserved for the external caller; pool workers take slots 1 … N−1.
        EXPECT_EQ(worker == 0, thread == caller) << "threads " << threads;
      }
    }
  }
}

// In a 2-slot arena the layout pins every index: the caller always holds slot 0, and any pool
// worker can only ever occupy slot 1. Over a run of many calls, each OS thread reports one index.
// (With more slots a worker that leaves the arena and rejoins normally gets its old slot back,
// but oneTBB does not promise it, so that is not asserted: see TaskSystem.h.)
TEST(TaskSystem, WorkerIndexIsStablePerThreadAcrossARun) {
  AllowThreads allow(2);
  TaskSystem tasks({.threadCount = 2});
  std::map<std::thread::id, int> indexOfThread;
  for (int call = 0; call < 200; ++call) {
    for (const auto& [thread, worker] : recordWorkers(tasks, 64)) {
      const auto [it, inserted] = indexOfThread.emplace(thread, worker);
      ASSERT_EQ(it->second, worker) << "a thread reported two worker indices, call " << call;
    }
  }
  EXPECT_EQ(indexOfThread.at(std::this_thread::get_id()), 0);
}

TEST(TaskSystem, ConcurrentBlocksNeverShareAWorkerIndexOrItsScratch) {
  AllowThreads allow(8);
  for (int threads : {2, 8}) {
    TaskSystem tasks({.threadCount = threads});
    struct Scratch {
      std::atomic<int> busy{0};
      std::vector<Index> candidates;  // reused across blocks: the real use of scratch
      Index blocksRun = 0;
    };
    PerWorker<Scratch> scratch(tasks);
    ASSERT_EQ(scratch.size(), threads);
    std::atomic<int> collisions{0};
    std::atomic<Index> mismatches{0};
    const Index count = 4000;
    tasks.parallelFor(count, 8, [&](Index begin, Index end, int worker) {
      Scratch& mine = scratch[worker];
      if (mine.busy.exchange(1) != 0) collisions.fetch_add(1);
      mine.candidates.clear();
      for (Index i = begin; i < end; ++i) mine.candidates.push_back(i);
      busyWork(begin, end);  // hold the scratch while others run
      // Nobody else wrote into our scratch while we held it.
      for (Index i = begin; i < end; ++i) mismatches += mine.candidates[i - begin] != i;
      mismatches += mine.candidates.size() != end - begin;
      ++mine.blocksRun;
      mine.busy.store(0);
    });
    EXPECT_EQ(collisions.load(), 0) << "threads " << threads;
    EXPECT_EQ(mismatches.load(), 0u) << "threads " << threads;
    Index totalBlocks = 0;
    scratch.forEach([&](Scratch& s) { totalBlocks += s.blocksRun; });
    EXPECT_EQ(totalBlocks, TaskSystem::blockCount(count, 8));
  }
}

TEST(PerWorker, SlotsAreConstructedOnceAndDoNotShareCacheLines) {
  AllowThreads allow(4);
  TaskSystem tasks({.threadCount = 4});
  PerWorker<std::vector<int>> scratch(tasks, std::size_t{3}, 7);
  ASSERT_EQ(scratch.size(), 4);
  for (int worker = 0; worker < scratch.size(); ++worker) {
    EXPECT_EQ(scratch[worker], (std::vector<int>{7, 7, 7}));
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(&scratch[worker]) % kFalseSharingBytes, 0u);
  }
  for (int worker = 1; worker < scratch.size(); ++worker) {
    const auto distance = reinterpret_cast<std::uintptr_t>(&scratch[worker]) -
                          reinterpret_cast<std::uintptr_t>(&scratch[worker - 1]);
    EXPECT_GE(distance, kFalseSharingBytes);
  }
  scratch[2].push_back(1);
  PerWorker<std::vector<int>> moved(std::move(scratch));
  EXPECT_EQ(moved[2].size(), 4u);
  EXPECT_EQ(scratch.size(), 0);
}

/// Values whose sum depends on the order of addition: magnitudes from 1e-20 to 1e20, both signs.
std::vector<double> wildValues(Index count) {
  std::mt19937_64 random(20240611);
  std::vector<double> values(count);
  for (double& value : values) {
    const int exponent = static_cast<int>(random() % 41) - 20;
    const double mantissa = 1.0 + static_cast<double>(random() % 1000000) * 1e-6;
    value = (random() % 2 == 0 ? 1.0 : -1.0) * mantissa * std::pow(10.0, exponent);
  }
  return values;
}

TEST(TaskSystem, OrderedReductionIsBitwiseIdenticalOnOneTwoAndEightThreads) {
  AllowThreads allow(8);
  const Index count = 100000;
  const std::vector<double> values = wildValues(count);

  // The data is order-sensitive: summing it backwards gives other bits. Otherwise this test
  // could not fail.
  double forward = 0.0, backward = 0.0;
  for (Index i = 0; i < count; ++i) forward += values[i];
  for (Index i = count; i-- > 0;) backward += values[i];
  ASSERT_NE(forward, backward);

  const auto blockSum = [&](Index begin, Index end) {
    double sum = 0.0;
    for (Index i = begin; i < end; ++i) sum += values[i];
    return sum;
  };
  const auto add = [](double a, double b) { return a + b; };

  TaskSystem serial({.threadCount = 1});
  TaskSystem two({.threadCount = 2});
  TaskSystem eight({.threadCount = 8});
  for (Index grain : {1u, 7u, 64u, 1000u, 4096u}) {
    // The reference: block partials folded left to right, written out by hand.
    double expected = 0.0;
    for (Index begin = 0; begin < count; begin += grain) expected += blockSum(begin, std::min(count, begin + grain));

    const double reference = serial.parallelReduce(count, grain, 0.0, blockSum, add);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(reference), std::bit_cast<std::uint64_t>(expected)) << "grain " << grain;
    for (int run = 0; run < 10; ++run) {
      const double onTwo = two.parallelReduce(count, grain, 0.0, blockSum, add);
      const double onEight = eight.parallelReduce(count, grain, 0.0, blockSum, add);
      EXPECT_EQ(onTwo, reference) << "grain " << grain;
      EXPECT_EQ(onEight, reference) << "grain " << grain;
      EXPECT_EQ(std::bit_cast<std::uint64_t>(onTwo), std::bit_cast<std::uint64_t>(reference));
      EXPECT_EQ(std::bit_cast<std::uint64_t>(onEight), std::bit_cast<std::uint64_t>(reference));
    }
  }
}

TEST(TaskSystem, ReductionCombinesPartialsInBlockOrder) {
  AllowThreads allow(8);
  TaskSystem tasks({.threadCount = 8});
  // A non-commutative combine: the fold records the order in which it saw the partials.
  struct Trace {
    std::uint64_t hash;
    Index blocks;
  };
  const Index count = 10000, grain = 37;
  const auto blockFn = [&](Index begin, Index end) {
    busyWork(begin, std::min(end, begin + 2));
    return Trace{begin * 1000003ull + end, 1};
  };
  const auto combine = [](Trace acc, Trace partial) {
    return Trace{acc.hash * 0x100000001B3ull ^ partial.hash, acc.blocks + partial.blocks};
  };
  Trace expected{14695981039346656037ull, 0};
  for (Index begin = 0; begin < count; begin += grain) expected = combine(expected, blockFn(begin, std::min(count, begin + grain)));
  for (int run = 0; run < 10; ++run) {
    const Trace got = tasks.parallelReduce(count, grain, Trace{14695981039346656037ull, 0}, blockFn, combine);
    EXPECT_EQ(got.hash, expected.hash);
    EXPECT_EQ(got.blocks, TaskSystem::blockCount(count, grain));
  }
}

TEST(TaskSystem, ReductionOfNothingIsTheIdentity) {
  TaskSystem tasks({.threadCount = 2});
  int calls = 0;
  const double result = tasks.parallelReduce(
      0, 16, 42.0, [&](Index, Index) { ++calls; return 1.0; }, [](double a, double b) { return a + b; });
  EXPECT_EQ(result, 42.0);
  EXPECT_EQ(calls, 0);
}

TEST(TaskSystem, NestedLoopsAndReductionsStayCorrect) {
  AllowThreads allow(4);
  TaskSystem tasks({.threadCount = 4});
  const Index outer = 64, inner = 500;
  std::vector<std::atomic<int>> visits(outer * inner);
  std::atomic<int> badWorker{0};
  std::vector<double> innerSums(outer);
  // Reference sums of each row, computed serially.
  TaskSystem serial({.threadCount = 1});
  const auto rowSum = [](Index row) {
    return [row](Index begin, Index end) {
      double sum = 0.0;
      for (Index i = begin; i < end; ++i) sum += 1.0 / (1.0 + row * 1000.0 + i);
      return sum;
    };
  };
  const auto add = [](double a, double b) { return a + b; };

  const double total = tasks.parallelReduce(outer, 4, 0.0, [&](Index begin, Index end) {
    double sum = 0.0;
    for (Index row = begin; row < end; ++row) {
      tasks.parallelFor(inner, 64, [&](Index b, Index e, int worker) {
        if (worker < 0 || worker >= tasks.threadCount()) badWorker.fetch_add(1);
        for (Index i = b; i < e; ++i) visits[row * inner + i].fetch_add(1);
      });
      // A nested reduce cannot use the shared partial buffer; it must still be exact.
      innerSums[row] = tasks.parallelReduce(inner, 64, 0.0, rowSum(row), add);
      sum += innerSums[row];
    }
    return sum;
  }, add);

  int wrong = 0;
  for (auto& v : visits) wrong += v.load() != 1;
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(badWorker.load(), 0);
  double expectedTotal = 0.0;
  for (Index begin = 0; begin < outer; begin += 4) {
    double sum = 0.0;
    for (Index row = begin; row < begin + 4; ++row) {
      const double expectedRow = serial.parallelReduce(inner, 64, 0.0, rowSum(row), add);
      EXPECT_EQ(innerSums[row], expectedRow) << "row " << row;
      sum += expectedRow;
    }
    expectedTotal += sum;
  }
  EXPECT_EQ(total, expectedTotal);
}

TEST(TaskSystem, UsesTheCallersArenaWithoutOwningIt) {
  AllowThreads allow(5);
  tbb::task_arena arena(5);
  {
    TaskSystem tasks(arena);
    EXPECT_EQ(tasks.threadCount(), 5);
    EXPECT_EQ(tasks.threadCount(), arena.max_concurrency());
    EXPECT_EQ(tasks.arena(), &arena);
    EXPECT_FALSE(tasks.isSerial());
    // Inside the blocks, the current arena is the caller's 5-slot arena (the machine has fewer
    // cores, so no default arena would report 5).
    std::atomic<int> wrongArena{0};
    std::atomic<int> badWorker{0};
    tasks.parallelFor(1000, 10, [&](Index, Index, int worker) {
      if (tbb::this_task_arena::max_concurrency() != 5) wrongArena.fetch_add(1);
      if (worker < 0 || worker >= 5) badWorker.fetch_add(1);
    });
    EXPECT_EQ(wrongArena.load(), 0);
    EXPECT_EQ(badWorker.load(), 0);
  }
  // The TaskSystem is gone; the arena is still the caller's and still works.
  EXPECT_TRUE(arena.is_active());
  int ran = 0;
  arena.execute([&] { ++ran; });
  EXPECT_EQ(ran, 1);
}

TEST(TaskSystem, OneSlotCallerArenaIsTheSerialPath) {
  tbb::task_arena arena(1);
  TaskSystem tasks(arena);
  EXPECT_EQ(tasks.threadCount(), 1);
  EXPECT_TRUE(tasks.isSerial());
}

TEST(TaskSystem, SerialModeRunsBlocksInOrderOnTheCallersThread) {
  TaskSystem tasks({.threadCount = 1});
  EXPECT_EQ(tasks.threadCount(), 1);
  EXPECT_TRUE(tasks.isSerial());
  EXPECT_EQ(tasks.arena(), nullptr);
  const std::thread::id caller = std::this_thread::get_id();
  std::vector<Index> begins;
  bool allOnCaller = true, allWorkerZero = true;
  tasks.parallelFor(100, 7, [&](Index begin, Index, int worker) {
    allOnCaller = allOnCaller && std::this_thread::get_id() == caller;
    allWorkerZero = allWorkerZero && worker == 0;
    begins.push_back(begin);  // unsynchronised on purpose: serial means one thread
  });
  EXPECT_TRUE(allOnCaller);
  EXPECT_TRUE(allWorkerZero);
  ASSERT_EQ(begins.size(), TaskSystem::blockCount(100, 7));
  for (std::size_t k = 0; k < begins.size(); ++k) EXPECT_EQ(begins[k], k * 7);
}

TEST(TaskSystem, SingleBlockRunsInlineOnTheCaller) {
  TaskSystem tasks({.threadCount = 2});
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id ranOn;
  int workerSeen = -1, calls = 0;
  tasks.parallelFor(50, 64, [&](Index begin, Index end, int worker) {
    ranOn = std::this_thread::get_id();
    workerSeen = worker;
    ++calls;
    EXPECT_EQ(begin, 0u);
    EXPECT_EQ(end, 50u);
  });
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(ranOn, caller);
  EXPECT_EQ(workerSeen, 0);
}

// The block counts GrainSizes.h argues from; if a constant changes, update its comment too.
TEST(GrainSizes, GiveTheCurtainTheBlockCountsTheirCommentsClaim) {
  constexpr Index curtainVertices = 41 * 31, curtainTriangles = 2400, x16Vertices = 161 * 121;
  EXPECT_EQ(TaskSystem::blockCount(curtainVertices, kGrainVertices), 1u);  // inline, no fork
  EXPECT_EQ(TaskSystem::blockCount(x16Vertices, kGrainVertices), 10u);
  EXPECT_EQ(TaskSystem::blockCount(curtainTriangles, kGrainElements), 38u);
  EXPECT_EQ(TaskSystem::blockCount(curtainVertices, kGrainMatrixRows), 10u);
}

}  // namespace
}  // namespace weft
