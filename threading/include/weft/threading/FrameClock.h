// FrameClock: the one clock that frame timings and profiler zones read.
//
// std::chrono::steady_clock (CLOCK_MONOTONIC on Linux, read through the vDSO in ~20 ns): it never
// jumps when the wall clock is adjusted, so differences are durations. Times are plain int64
// nanoseconds so that they can be stored in preallocated event buffers and subtracted without
// chrono casts at every call site.
#pragma once

#include <chrono>
#include <cstdint>

namespace weft {

/// Monotonic time in integer nanoseconds and conversions between two such readings.
class FrameClock {
 public:
  /// Nanoseconds on the steady clock; only differences between two readings mean anything.
  static std::int64_t nowNs() noexcept {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }

  /// Milliseconds from beginNs to endNs (negative if endNs is earlier).
  static constexpr double msBetween(std::int64_t beginNs, std::int64_t endNs) noexcept {
    return static_cast<double>(endNs - beginNs) * 1e-6;
  }

  /// Microseconds from beginNs to endNs (negative if endNs is earlier).
  static constexpr double usBetween(std::int64_t beginNs, std::int64_t endNs) noexcept {
    return static_cast<double>(endNs - beginNs) * 1e-3;
  }

  /// Milliseconds since startNs, read now.
  static double msSince(std::int64_t startNs) noexcept { return msBetween(startNs, nowNs()); }
};

}  // namespace weft
