// ClothStatistics: shape statistics that converge where a trajectory does not. Where the cloth's
// motion is chaotic (a free hem beside a pushing body, folds in self-contact) two accurate runs
// part, and so do their states at any one instant; what they share is the distribution over a
// stretch of time: the strains of every edge at every sample pooled, and how often each point of
// the outline is covered. Used by weft-error-time to rank phases whose vertex distances the
// reference cannot resolve.
#pragma once

#include <weft/Math.h>
#include <weft/engine/ClothModel.h>

#include <array>
#include <cstdint>
#include <vector>

namespace weft {

/// Percentiles of the mesh edges' strain l / l_rest − 1: 50 %, 90 %, 99 % and the largest.
using StrainPercentiles = std::array<Real, 4>;

/// The strains of `model`'s edges at `positions`, appended to `strains`.
void appendEdgeStrains(const ClothModel& model, const Vec3Array& positions,
                       std::vector<Real>& strains);

/// The percentiles of `strains` (sorts them): of one state's edges, or of several states pooled.
StrainPercentiles strainPercentiles(std::vector<Real>& strains);

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

/// How often each cell of a grid is covered over several outlines: the fraction per cell.
struct Coverage {
  std::vector<Real> fraction;  ///< in [0, 1], per cell
  Index outlines = 0;          ///< outlines added
  Index coveredCells = 0;      ///< covered cells, summed over the outlines added

  /// Counts one outline of the grid.
  void add(const Silhouette& silhouette);
  /// Turns the counts into fractions (call once, after the last add()).
  void finish();
};

/// Σ |a − b| / Σ max(a, b) over the cells (the weighted Jaccard distance): 1 − IoU for single
/// outlines, 0 for the same coverage, 1 for disjoint ones.
Real coverageDistance(const Coverage& a, const Coverage& b);

}  // namespace weft
