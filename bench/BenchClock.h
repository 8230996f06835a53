// BenchClock: the two clocks the benches read, in milliseconds.
#pragma once

#include <ctime>

namespace weft::bench {

/// ms of CPU time the calling thread has used: unaffected by other processes on a shared machine.
inline double threadCpuMs() {
  timespec time{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &time);
  return 1e3 * static_cast<double>(time.tv_sec) + 1e-6 * static_cast<double>(time.tv_nsec);
}

/// ms of monotonic wall-clock time.
inline double wallMs() {
  timespec time{};
  clock_gettime(CLOCK_MONOTONIC, &time);
  return 1e3 * static_cast<double>(time.tv_sec) + 1e-6 * static_cast<double>(time.tv_nsec);
}

}  // namespace weft::bench
