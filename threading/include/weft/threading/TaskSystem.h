// TaskSystem: the one parallel primitive of Weft, deterministic by construction.
//
// Design note
// -----------
// Everything parallel in the engine goes through parallelFor(count, grain, fn(begin, end, worker))
// (Box2D's parallel_for.h shape). Three decisions make it deterministic and embeddable:
//
// * Fixed blocks. [0, count) is cut into blocks [k·grain, min((k+1)·grain, count)), k = 0 …
//   blockCount − 1. The cut depends only on (count, grain), never on the number of threads or on
//   timing, so whatever a block computes (a partial sum, a list of contacts) is the same on 1 or
//   N threads; only *which thread* runs a block varies. The blocks are handed to oneTBB as a
//   blocked_range over block indices with grainsize 1 and simple_partitioner, so every leaf task
//   is exactly one block.
//   Rejected: auto_partitioner / affinity_partitioner and tbb::parallel_reduce over the element
//   range. Their splits adapt to stealing (a range is split further when a thief shows up), so
//   where a partial sum starts and ends depends on timing, and floating-point sums change bits
//   from run to run. tbb::parallel_deterministic_reduce is reproducible, but it halves ranges
//   recursively (its pieces are not parallelFor's k·grain blocks) and combines in a tree, so the
//   serial reference would have to mimic that tree; here it is a plain left fold, and combine
//   need not even be associative.
//
// * Ordered reductions. parallelReduce stores one partial per block in a buffer owned by the
//   TaskSystem (reused: no allocation after the first frame) and folds them in block order on
//   the calling thread: acc = combine(…combine(combine(identity, p0), p1)…, pB−1). The result is
//   bitwise identical for any thread count, including the serial reference.
//
// * A task_arena the caller controls. A TaskSystem runs its blocks inside one tbb::task_arena of
//   N slots: either its own (Settings::threadCount) or one the caller passes in and keeps owning.
//   Why an arena and not plain tbb::parallel_for: the arena caps concurrency per engine instance
//   (a game can give the cloth 2 of its 8 cores), isolates our tasks from the host's, and gives
//   every thread inside it a slot index in [0, N) — the workerIndex that indexes PerWorker
//   scratch. A slot is held by one thread at a time, so two blocks running at the same moment
//   never share a workerIndex, and a block keeps its index from start to end. Slot 0 is
//   reserved for the external caller; pool workers take slots 1 … N−1. A worker that leaves
//   the arena (out of work) and rejoins tries the slot it held last first (oneTBB arena.cpp,
//   occupy_free_slot_in_range), so a thread normally keeps its index across calls; but oneTBB
//   does not promise it (another pool thread may have taken that slot), so per-worker state
//   must be scratch whose meaning does not depend on which thread owns it.
//   Rejected: std::thread pools of our own (a second scheduler fighting TBB's for the same cores,
//   and threads spawned behind the host's back); tbb::enumerable_thread_specific for scratch
//   (keyed by OS thread, unbounded count, a hash lookup per access).
//
// threadCount == 1 is the serial reference: blocks run in order on the calling thread, no TBB
// call at all, workerIndex 0. A single-block call (count ≤ grain) also runs inline: no fork.
//
// Threads: oneTBB supplies arena workers from its global pool, whose size defaults to the
// machine's cores; an arena wider than the machine gets more slots (workerIndex range) but no
// more threads unless the host raises tbb::global_control::max_allowed_parallelism. A TaskSystem
// never does that itself.
//
// Contract: one external thread drives a TaskSystem at a time (as World::step does); fn may call
// parallelFor / parallelReduce again (nested), which then runs inside the same arena.
#pragma once

#include <oneapi/tbb/blocked_range.h>
#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/partitioner.h>
#include <oneapi/tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <type_traits>

namespace weft {

class TaskSystem;

namespace detail {
/// The TaskSystem whose block the calling thread is running (nullptr outside any block): lets an
/// inline nested call report the thread's own slot instead of 0.
inline constinit thread_local const TaskSystem* t_activeTaskSystem = nullptr;

/// Sets t_activeTaskSystem for the duration of one block and restores the outer value.
class ActiveTaskSystemScope {
 public:
  explicit ActiveTaskSystemScope(const TaskSystem* tasks) noexcept : m_previous(t_activeTaskSystem) {
    t_activeTaskSystem = tasks;
  }
  ~ActiveTaskSystemScope() { t_activeTaskSystem = m_previous; }
  ActiveTaskSystemScope(const ActiveTaskSystemScope&) = delete;
  ActiveTaskSystemScope& operator=(const ActiveTaskSystemScope&) = delete;

 private:
  const TaskSystem* m_previous;
};

/// Raw, 64-byte aligned, growable storage for the per-block partials of parallelReduce.
class PartialBuffer {
 public:
  PartialBuffer() = default;
  ~PartialBuffer();
  PartialBuffer(const PartialBuffer&) = delete;
  PartialBuffer& operator=(const PartialBuffer&) = delete;

  /// At least `bytes` bytes, 64-byte aligned; grows (and forgets the old contents) when needed.
  void* reserve(std::size_t bytes);

  /// Bytes currently allocated.
  std::size_t capacity() const { return m_capacity; }

  /// Alignment of the storage.
  static constexpr std::size_t kAlignment = 64;

 private:
  void* m_data = nullptr;
  std::size_t m_capacity = 0;
};
}  // namespace detail

/// How a TaskSystem builds its own arena (TaskSystem::Settings).
struct TaskSystemSettings {
  int threadCount = 0;  ///< threads incl. the caller, 0 … kMaxThreadCount; 0 = the machine's
                        ///< cores, 1 = serial reference (inline, no TBB). More than the cores only
                        ///< helps if the host raised tbb::global_control::max_allowed_parallelism.
  /// The most threads a TaskSystem takes (per-worker scratch is sized by the count).
  static constexpr int kMaxThreadCount = 1024;
};

/// Empty when `settings` are valid; otherwise what is wrong, naming the field and the fix.
std::string validate(const TaskSystemSettings& settings);

/// Runs deterministic parallel loops over fixed blocks inside a oneTBB task_arena (or serially).
class TaskSystem {
 public:
  /// Element index and count type; the same as weft::Index (collision/Math.h), which sits above
  /// this module and so cannot be included here.
  using Index = std::uint32_t;

  /// How a TaskSystem builds its own arena.
  using Settings = TaskSystemSettings;

  /// Creates an arena of settings.threadCount slots (none in serial mode). Worker threads come
  /// from oneTBB's pool on first use; no thread is created here. Settings that validate()
  /// refuses give the serial reference (check them first to report the mistake).
  explicit TaskSystem(Settings settings = {});

  /// Runs on the caller's arena, which it does not own and which must outlive this object;
  /// threadCount() = arena.max_concurrency() (a 1-slot arena gives the serial path).
  explicit TaskSystem(tbb::task_arena& arena);

  ~TaskSystem();
  TaskSystem(const TaskSystem&) = delete;
  TaskSystem& operator=(const TaskSystem&) = delete;

  /// Number of worker slots: every workerIndex passed to fn lies in [0, threadCount()).
  int threadCount() const { return m_threadCount; }

  /// True for the serial reference (threadCount() == 1): everything runs inline on the caller.
  bool isSerial() const { return m_arena == nullptr; }

  /// The arena blocks run in, or nullptr in serial mode. For hosts that want to run their own
  /// TBB work alongside ours in the same arena.
  tbb::task_arena* arena() const { return m_arena; }

  /// Number of fixed blocks for count elements cut into pieces of grain: ⌈count / grain⌉.
  static constexpr Index blockCount(Index count, Index grain) {
    assert(grain > 0 && "TaskSystem: grain must be at least 1; use a kGrain constant from GrainSizes.h");
    return static_cast<Index>((std::uint64_t{count} + grain - 1) / grain);
  }

  /// Calls fn(begin, end, workerIndex) once for every block [k·grain, min((k+1)·grain, count)).
  /// Blocks may run concurrently and in any order; workerIndex is unique among blocks running at
  /// the same moment. Returns when all blocks are done. Serial mode and count ≤ grain run the
  /// blocks in order on the caller.
  template <class Fn>
  void parallelFor(Index count, Index grain, Fn&& fn);

  /// Ordered reduction: partial_k = blockFn(begin_k, end_k) for every fixed block k, then
  /// combine(…combine(combine(identity, partial_0), partial_1)…) in block order on the caller.
  /// Bitwise identical for every thread count. T must be trivially copyable (sums, bounds, small
  /// structs); combine need not be associative or commutative.
  template <class T, class BlockFn, class Combine>
  T parallelReduce(Index count, Index grain, T identity, BlockFn&& blockFn, Combine&& combine);

  /// The calling thread's workerIndex for this TaskSystem: its slot when called from inside one
  /// of our blocks, otherwise 0 (the external caller's slot).
  int currentWorkerIndex() const;

 private:
  /// End of the block starting at begin, computed in 64 bits so the last block near 2³² does
  /// not wrap.
  static constexpr Index blockEnd(Index begin, Index grain, Index count) {
    return static_cast<Index>(std::min<std::uint64_t>(std::uint64_t{begin} + grain, count));
  }

  template <class Fn>
  void runBlocksInline(Index count, Index grain, Index blocks, Fn& fn) const;

  std::unique_ptr<tbb::task_arena> m_ownedArena;  ///< set when we built the arena ourselves
  tbb::task_arena* m_arena = nullptr;             ///< where blocks run; nullptr = serial
  int m_threadCount = 1;                          ///< arena slots; 1 = serial
  detail::PartialBuffer m_partials;               ///< reused storage of parallelReduce partials
  std::atomic<bool> m_partialsInUse{false};       ///< set while a reduce uses m_partials; a
                                                  ///< nested / concurrent one takes its own buffer
};

// ---------------------------------------------------------------------------------------------

inline int TaskSystem::currentWorkerIndex() const {
  if (m_arena == nullptr || detail::t_activeTaskSystem != this) return 0;
  const int slot = tbb::this_task_arena::current_thread_index();
  assert(slot >= 0 && slot < m_threadCount && "TaskSystem: thread slot outside the arena");
  return slot;
}

template <class Fn>
void TaskSystem::runBlocksInline(Index count, Index grain, Index blocks, Fn& fn) const {
  const int worker = currentWorkerIndex();
  // Same blocks, same order as any parallel run: a block's result never depends on threads.
  for (Index block = 0; block < blocks; ++block) {
    const Index begin = block * grain;
    fn(begin, blockEnd(begin, grain, count), worker);
  }
}

template <class Fn>
void TaskSystem::parallelFor(Index count, Index grain, Fn&& fn) {
  const Index blocks = blockCount(count, grain);
  if (blocks == 0) return;
  if (m_arena == nullptr || blocks == 1) {
    runBlocksInline(count, grain, blocks, fn);
    return;
  }
  m_arena->execute([&] {
    // grainsize 1 + simple_partitioner: each leaf range holds exactly one block index, and the
    // block's element range is computed from it, never from how TBB happened to split.
    tbb::parallel_for(
        tbb::blocked_range<Index>(0, blocks, 1),
        [&](const tbb::blocked_range<Index>& range) {
          const int worker = tbb::this_task_arena::current_thread_index();
          assert(worker >= 0 && worker < m_threadCount &&
                 "TaskSystem: workerIndex outside [0, threadCount); was the arena resized?");
          detail::ActiveTaskSystemScope active(this);
          for (Index block = range.begin(); block != range.end(); ++block) {
            const Index begin = block * grain;
            fn(begin, blockEnd(begin, grain, count), worker);
          }
        },
        tbb::simple_partitioner());
  });
}

template <class T, class BlockFn, class Combine>
T TaskSystem::parallelReduce(Index count, Index grain, T identity, BlockFn&& blockFn,
                             Combine&& combine) {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                "TaskSystem::parallelReduce: partials live in raw reused storage; reduce a "
                "trivially copyable value (a sum, a bound, a small struct)");
  static_assert(alignof(T) <= detail::PartialBuffer::kAlignment,
                "TaskSystem::parallelReduce: partial type is over-aligned");
  const Index blocks = blockCount(count, grain);
  if (blocks == 0) return identity;
  if (blocks == 1) return combine(identity, blockFn(Index{0}, count));

  // The shared buffer serves the common case; a nested or concurrent reduce takes a private one
  // (allocates, but stays correct).
  const bool useShared = !m_partialsInUse.exchange(true, std::memory_order_acquire);
  detail::PartialBuffer privateBuffer;
  detail::PartialBuffer& buffer = useShared ? m_partials : privateBuffer;
  struct Release {
    std::atomic<bool>* flag;
    ~Release() {
      if (flag != nullptr) flag->store(false, std::memory_order_release);
    }
  } release{useShared ? &m_partialsInUse : nullptr};

  T* partials = static_cast<T*>(buffer.reserve(std::size_t{blocks} * sizeof(T)));
  parallelFor(count, grain, [&](Index begin, Index end, int) {
    // Each block writes only its own slot: no sharing, no locks.
    ::new (static_cast<void*>(partials + begin / grain)) T(blockFn(begin, end));
  });
  // Determinism: fold strictly in block order on this thread, whatever ran where.
  T result = identity;
  for (Index block = 0; block < blocks; ++block) {
    result = combine(result, *std::launder(partials + block));
  }
  return result;
}

}  // namespace weft
