// BenchClock: the clocks the benches read: the calling thread's CPU time and the wall clock.
#pragma once

#include <ctime>

namespace weft::bench {

/// s of CPU time the calling thread has used: unaffected by other processes on a shared machine.
inline double threadCpuSeconds() {
  timespec time{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &time);
  return static_cast<double>(time.tv_sec) + 1e-9 * static_cast<double>(time.tv_nsec);
}

/// ms of CPU time the calling thread has used (threadCpuSeconds).
inline double threadCpuMs() { return 1e3 * threadCpuSeconds(); }

/// ms of monotonic wall-clock time.
inline double wallMs() {
  timespec time{};
  clock_gettime(CLOCK_MONOTONIC, &time);
  return 1e3 * static_cast<double>(time.tv_sec) + 1e-6 * static_cast<double>(time.tv_nsec);
}

}  // namespace weft::bench
