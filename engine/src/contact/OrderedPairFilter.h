// OrderedPairFilter: runs a test over candidate pairs in parallel and keeps what passes in pair
// order. Which worker finds which result depends on timing; sorting by the pair index restores
// the serial order, so the result is the same bits on any number of threads. The workers' lists
// grow with the number of results, never with the timing of the threads.
#pragma once

#include <weft/threading/PerWorker.h>
#include <weft/threading/TaskSystem.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace weft {

template <typename Result>
class OrderedPairFilter {
 public:
  using Index = TaskSystem::Index;

  /// Uses `tasks` (null or serial: every run is serial).
  void build(TaskSystem* tasks) {
    m_tasks = tasks;
    if (m_tasks && !m_tasks->isSerial() && !m_workers) {
      m_workers = std::make_unique<PerWorker<std::vector<Found>>>(*m_tasks);
    }
  }

  /// Appends to `out`, in order of `pair`, every result for which `test(pair, result)` returns
  /// true, over pairs [0, total), in blocks of `grain` pairs. `result` starts value-initialised.
  template <typename Test>
  void run(Index total, Index grain, const Test& test, std::vector<Result>& out) {
    if (!m_workers || total <= grain) {
      Result result;
      for (Index pair = 0; pair < total; ++pair) {
        result = Result{};
        if (test(pair, result)) out.push_back(result);
      }
      return;
    }
    m_workers->forEach([](std::vector<Found>& found) { found.clear(); });
    m_tasks->parallelFor(total, grain, [&](Index begin, Index end, int worker) {
      std::vector<Found>& found = (*m_workers)[worker];
      Result result;
      for (Index pair = begin; pair < end; ++pair) {
        result = Result{};
        if (test(pair, result)) found.push_back({pair, result});
      }
    });
    m_merged.clear();
    m_workers->forEach([this](std::vector<Found>& found) {
      m_merged.insert(m_merged.end(), found.begin(), found.end());
    });
    std::sort(m_merged.begin(), m_merged.end(),
              [](const Found& a, const Found& b) { return a.pair < b.pair; });
    for (const Found& found : m_merged) out.push_back(found.result);
    const std::size_t count = m_merged.size();
    m_workers->forEach([count](std::vector<Found>& found) {
      if (found.capacity() < count) found.reserve(count);
    });
  }

 private:
  struct Found {
    Index pair;
    Result result;
  };
  TaskSystem* m_tasks = nullptr;
  std::unique_ptr<PerWorker<std::vector<Found>>> m_workers;
  std::vector<Found> m_merged;
};

}  // namespace weft
