// PerWorker<T>: one T per TaskSystem worker slot, for scratch that blocks reuse without locks.
//
// Indexed by the workerIndex that TaskSystem::parallelFor passes to fn. Two blocks running at the
// same moment never share a workerIndex, so a block may use scratch[workerIndex] freely for its
// whole duration. Which OS thread holds an index can change between calls (TaskSystem.h), so
// scratch is working memory, never a thread's identity. Each T sits in its own 128-byte aligned slot (two 64-byte lines: Intel's
// adjacent-line prefetcher and Apple's 128-byte lines) so workers never false-share.
//
// Determinism: which blocks a worker runs depends on timing, so scratch must not carry results
// out of a parallelFor in a way that depends on it (e.g. summing per-worker totals gives
// different bits on different thread counts). Keep it for temporaries — candidate lists, small
// matrices, stacks — and return results through per-block slots or TaskSystem::parallelReduce.
#pragma once

#include <weft/threading/TaskSystem.h>

#include <cassert>
#include <cstddef>
#include <memory>
#include <new>
#include <utility>

namespace weft {

/// Bytes between per-thread data so that two threads never write the same cache line pair.
inline constexpr std::size_t kFalseSharingBytes = 128;

/// One T per worker slot, constructed once, each on its own cache lines.
template <class T>
class PerWorker {
 public:
  /// workerCount copies of T(args...); workerCount must be ≥ the TaskSystem's threadCount().
  template <class... Args>
  explicit PerWorker(int workerCount, const Args&... args) : m_count(workerCount) {
    assert(workerCount >= 1 && "PerWorker: need at least one worker slot");
    m_slots = static_cast<Slot*>(
        ::operator new(sizeof(Slot) * static_cast<std::size_t>(m_count), std::align_val_t{alignof(Slot)}));
    int constructed = 0;
    try {
      for (; constructed < m_count; ++constructed) ::new (static_cast<void*>(m_slots + constructed)) Slot(args...);
    } catch (...) {
      destroy(constructed);
      throw;
    }
  }

  /// One T(args...) per worker slot of tasks.
  template <class... Args>
  explicit PerWorker(const TaskSystem& tasks, const Args&... args) : PerWorker(tasks.threadCount(), args...) {}

  ~PerWorker() { destroy(m_count); }

  PerWorker(const PerWorker&) = delete;
  PerWorker& operator=(const PerWorker&) = delete;

  /// Takes other's slots; other is left empty (size() == 0).
  PerWorker(PerWorker&& other) noexcept
      : m_slots(std::exchange(other.m_slots, nullptr)), m_count(std::exchange(other.m_count, 0)) {}

  /// Takes other's slots after releasing ours; other is left empty.
  PerWorker& operator=(PerWorker&& other) noexcept {
    if (this != &other) {
      destroy(m_count);
      m_slots = std::exchange(other.m_slots, nullptr);
      m_count = std::exchange(other.m_count, 0);
    }
    return *this;
  }

  /// The scratch of workerIndex (as passed to a parallelFor fn).
  T& operator[](int workerIndex) {
    assert(workerIndex >= 0 && workerIndex < m_count &&
           "PerWorker: workerIndex out of range; build PerWorker from the TaskSystem that runs the loop");
    return m_slots[workerIndex].value;
  }

  /// The scratch of workerIndex, read-only.
  const T& operator[](int workerIndex) const {
    assert(workerIndex >= 0 && workerIndex < m_count &&
           "PerWorker: workerIndex out of range; build PerWorker from the TaskSystem that runs the loop");
    return m_slots[workerIndex].value;
  }

  /// Number of worker slots.
  int size() const { return m_count; }

  /// Calls fn(T&) for every slot in worker order (between parallel loops, e.g. to reset).
  template <class Fn>
  void forEach(Fn&& fn) {
    for (int worker = 0; worker < m_count; ++worker) fn(m_slots[worker].value);
  }

 private:
  struct alignas(kFalseSharingBytes) Slot {
    template <class... Args>
    explicit Slot(const Args&... args) : value(args...) {}
    T value;
  };

  void destroy(int constructed) noexcept {
    if (m_slots == nullptr) return;
    for (int worker = 0; worker < constructed; ++worker) m_slots[worker].~Slot();
    ::operator delete(m_slots, std::align_val_t{alignof(Slot)});
    m_slots = nullptr;
  }

  Slot* m_slots = nullptr;
  int m_count = 0;
};

}  // namespace weft
