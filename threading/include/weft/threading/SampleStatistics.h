// Statistics of per-frame samples (frame times, iteration counts) for the reports of the curtain
// runner, the weft command line and the peer comparison: one nearest-rank percentile, so their
// figures compare.
//
// Nearest rank: of n samples sorted x₁ ≤ … ≤ xₙ, the p-th percentile is x_k with k = ⌈p·n / 100⌉
// (k = 1 for p = 0): the smallest sample that at least p % of the samples do not exceed. It is
// always one of the samples (p50 of an even count is the lower middle one, never an average), so
// a p99 frame time is a frame that happened. The rank is computed as ⌈(p·n) / 100⌉, not
// ⌈(p / 100)·n⌉: p / 100 is inexact (7 / 100 · 100 = 7.000000000000001 rounds up to rank 8).
//
// Contract: no samples → 0; p outside [0, 100] is clamped to it; a NaN sample or a NaN p → NaN,
// so that a broken measurement shows in the report instead of being sorted into a rank at random
// (std::sort's order is undefined with NaN). Infinities are ordinary samples.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace weft {

/// The p-th percentile (0 ≤ p ≤ 100, clamped) of samples, by the nearest-rank method; 0 when
/// empty, NaN when p or a sample is NaN.
inline double percentile(std::vector<double> samples, double p) {
  if (samples.empty()) return 0;
  const auto isNan = [](double x) { return std::isnan(x); };
  if (std::isnan(p) || std::any_of(samples.begin(), samples.end(), isNan)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  std::sort(samples.begin(), samples.end());
  const double n = double(samples.size());
  const double rank = std::ceil(std::clamp(p, 0.0, 100.0) * n / 100.0);
  const std::size_t index = std::size_t(std::clamp(rank, 1.0, n)) - 1;
  return samples[index];
}

/// Arithmetic mean; 0 when empty, NaN when a sample is NaN.
inline double mean(const std::vector<double>& samples) {
  if (samples.empty()) return 0;
  return std::accumulate(samples.begin(), samples.end(), 0.0) / double(samples.size());
}

}  // namespace weft
