// Statistics of per-frame samples (frame times, iteration counts) for the reports of the curtain
// runner, the weft command line and the peer comparison: one nearest-rank percentile, so their
// figures compare.
#pragma once

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace weft {

/// The p-th percentile (0 ≤ p ≤ 100) of samples, by the nearest-rank method; 0 when empty.
inline double percentile(std::vector<double> samples, double p) {
  if (samples.empty()) return 0;
  std::sort(samples.begin(), samples.end());
  const double rank = std::ceil(p / 100.0 * double(samples.size()));
  const std::size_t index = std::size_t(std::clamp(rank, 1.0, double(samples.size()))) - 1;
  return samples[index];
}

/// Arithmetic mean; 0 when empty.
inline double mean(const std::vector<double>& samples) {
  if (samples.empty()) return 0;
  return std::accumulate(samples.begin(), samples.end(), 0.0) / double(samples.size());
}

}  // namespace weft
