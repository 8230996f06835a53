#include "ClothStatistics.h"

#include <algorithm>
#include <cmath>

namespace weft {

void appendEdgeStrains(const ClothModel& model, const Vec3Array& positions,
                       std::vector<Real>& strains) {
  for (const Edge& edge : model.edges()) {
    const Real length = (positions[edge.vertices[1]] - positions[edge.vertices[0]]).norm();
    strains.push_back(length / edge.restLength - 1);
  }
}

StrainPercentiles strainPercentiles(std::vector<Real>& strains) {
  std::sort(strains.begin(), strains.end());
  StrainPercentiles result{};
  if (strains.empty()) return result;
  const auto at = [&](Real fraction) {
    return strains[std::min(strains.size() - 1, std::size_t(fraction * Real(strains.size())))];
  };
  result = {at(0.5), at(0.9), at(0.99), strains.back()};
  return result;
}

Silhouette SilhouetteGrid::rasterize(const std::vector<Index>& indices,
                                     const Vec3Array& positions) const {
  const int a = viewAxis == 0 ? 1 : 0;
  const int b = viewAxis == 2 ? 1 : 2;
  Silhouette silhouette;
  silhouette.covered.assign(std::size_t(cells[0]) * std::size_t(cells[1]), 0);
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    Vec2 p[3];
    for (int k = 0; k < 3; ++k) {
      const Vec3& x = positions[indices[t + std::size_t(k)]];
      p[k] = Vec2((x[a] - minimum[0]) / cell, (x[b] - minimum[1]) / cell);
    }
    const Real area = (p[1] - p[0]).x() * (p[2] - p[0]).y() - (p[1] - p[0]).y() * (p[2] - p[0]).x();
    if (area == 0 || !std::isfinite(area)) continue;
    const int x0 = std::max(0, int(std::floor(std::min({p[0].x(), p[1].x(), p[2].x()}))));
    const int x1 = std::min(cells[0] - 1, int(std::ceil(std::max({p[0].x(), p[1].x(), p[2].x()}))));
    const int y0 = std::max(0, int(std::floor(std::min({p[0].y(), p[1].y(), p[2].y()}))));
    const int y1 = std::min(cells[1] - 1, int(std::ceil(std::max({p[0].y(), p[1].y(), p[2].y()}))));
    for (int j = y0; j <= y1; ++j) {
      for (int i = x0; i <= x1; ++i) {
        const Vec2 c(i + 0.5, j + 0.5);
        // Inside when the three edge functions share the triangle's orientation.
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const Vec2& u = p[k];
          const Vec2& v = p[(k + 1) % 3];
          const Real edge = (v - u).x() * (c - u).y() - (v - u).y() * (c - u).x();
          inside = area > 0 ? edge >= 0 : edge <= 0;
        }
        if (inside) silhouette.covered[std::size_t(j) * std::size_t(cells[0]) + std::size_t(i)] = 1;
      }
    }
  }
  silhouette.coveredCells = Index(std::count(silhouette.covered.begin(), silhouette.covered.end(), 1));
  return silhouette;
}

void Coverage::add(const Silhouette& silhouette) {
  if (fraction.empty()) fraction.assign(silhouette.covered.size(), 0);
  if (fraction.size() != silhouette.covered.size()) return;
  for (std::size_t k = 0; k < fraction.size(); ++k) fraction[k] += silhouette.covered[k];
  coveredCells += silhouette.coveredCells;
  ++outlines;
}

void Coverage::finish() {
  if (outlines == 0) return;
  for (Real& value : fraction) value /= Real(outlines);
}

Real coverageDistance(const Coverage& a, const Coverage& b) {
  if (a.fraction.size() != b.fraction.size()) return 1;
  Real difference = 0, either = 0;
  for (std::size_t k = 0; k < a.fraction.size(); ++k) {
    difference += std::abs(a.fraction[k] - b.fraction[k]);
    either += std::max(a.fraction[k], b.fraction[k]);
  }
  return either == 0 ? 0 : difference / either;
}

}  // namespace weft
