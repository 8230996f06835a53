// forEachBlock: the loops of the collision module that may run in parallel.
//
// With a TaskSystem the blocks go through TaskSystem::parallelFor; without one (nullptr) they run
// in order on the caller. Either way the blocks are the same fixed ranges
// [k·grain, min((k+1)·grain, count)) and every block writes only its own slots, so the results
// are the same bits on any number of threads.
#pragma once

#include <weft/Math.h>
#include <weft/threading/TaskSystem.h>

namespace weft::detail {

/// Calls fn(begin, end, workerIndex) for the blocks [k·grain, min((k+1)·grain, count)): through
/// tasks->parallelFor when tasks is given, else in order on the caller with workerIndex 0.
template <typename Fn>
void forEachBlock(TaskSystem* tasks, Index count, Index grain, Fn&& fn) {
  if (tasks != nullptr) {
    tasks->parallelFor(count, grain, fn);
    return;
  }
  for (Index begin = 0; begin < count;) {
    const Index end = count - begin > grain ? begin + grain : count;
    fn(begin, end, 0);
    begin = end;
  }
}

}  // namespace weft::detail
