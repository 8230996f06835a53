// ClothStatistics: shape statistics of a cloth state that converge where its trajectory does
// not (folded, self-contacting cloth is chaotic: two accurate runs fold differently, but their
// strain distribution and outline agree). Used by weft-error-time to rank phases whose vertex
// distances the reference cannot resolve.
#pragma once

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>

#include <array>
#include <cstdint>
#include <vector>

namespace weft {

/// Percentiles of the mesh edges' strain l / l_rest − 1: 50 %, 90 %, 99 % and the largest.
using StrainPercentiles = std::array<Real, 4>;

/// The edge-strain percentiles of `positions` on `model`'s edges.
StrainPercentiles strainPercentiles(const ClothModel& model, const Vec3Array& positions);

/// The cloth's outline seen along the view axis: a raster of the cells its triangles cover.
struct Silhouette {
  std::vector<std::uint8_t> covered;  ///< 1 where a triangle covers the cell centre
  Index coveredCells = 0;
};

/// A fixed raster window in the plane across `viewAxis` (0 = x, 1 = y, 2 = z), cells of `cell`
/// metres, wide enough for the curtain's script (x in [−1.2, 1.2] m, y in [0, 2.2] m for z).
struct SilhouetteGrid {
  int viewAxis = 2;
  Real cell = 0.01;              ///< m
  Real minimum[2] = {-1.2, 0.0};  ///< m, lower corner in the two in-plane axes
  int cells[2] = {240, 220};

  /// Rasterises every triangle of the mesh (indices in threes) at these positions.
  Silhouette rasterize(const std::vector<Index>& indices, const Vec3Array& positions) const;
};

/// 1 − |a ∩ b| / |a ∪ b|: 0 for the same outline, 1 for disjoint ones.
Real silhouetteDistance(const Silhouette& a, const Silhouette& b);

}  // namespace weft
