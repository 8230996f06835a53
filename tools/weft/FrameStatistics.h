// Per-frame timing statistics for the command line's reports: nearest-rank percentiles (the
// method weft-curtain reports with, so the two programs' figures compare).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace weft {

/// Nearest-rank p-th percentile (0 < p ≤ 100) of samples; 0 when there are none.
inline double nearestRankPercentile(std::vector<double> samples, double p) {
  if (samples.empty()) return 0;
  std::sort(samples.begin(), samples.end());
  const double rank = std::ceil(p / 100.0 * double(samples.size()));
  return samples[std::size_t(std::clamp(rank, 1.0, double(samples.size()))) - 1];
}

}  // namespace weft
