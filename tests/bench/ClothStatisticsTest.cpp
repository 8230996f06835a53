// The statistics weft-error-time ranks chaotic phases by (bench/ClothStatistics.h), tested alone.
#include "ClothStatistics.h"

#include <gtest/gtest.h>

#include <vector>

namespace weft {
namespace {

Silhouette outline(std::vector<std::uint8_t> covered) {
  Silhouette silhouette;
  silhouette.covered = std::move(covered);
  for (std::uint8_t cell : silhouette.covered) silhouette.coveredCells += cell;
  return silhouette;
}

Coverage coverageOf(std::initializer_list<Silhouette> outlines) {
  Coverage coverage;
  for (const Silhouette& silhouette : outlines) coverage.add(silhouette);
  coverage.finish();
  return coverage;
}

TEST(ClothStatistics, TheCoverageDistanceOfSingleOutlinesIsOneMinusTheirIntersectionOverUnion) {
  // Cells {0, 1} against {1, 2}: one shared of three covered.
  const Coverage a = coverageOf({outline({1, 1, 0, 0})});
  const Coverage b = coverageOf({outline({0, 1, 1, 0})});
  EXPECT_DOUBLE_EQ(coverageDistance(a, b), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(coverageDistance(a, a), 0.0);
  EXPECT_DOUBLE_EQ(coverageDistance(a, coverageOf({outline({0, 0, 1, 1})})), 1.0);
}

TEST(ClothStatistics, OutlinesThatTakeTurnsHaveTheCoverageOfTheirMixture) {
  // Two runs that flap out of phase (cell 0 then 1, against 1 then 0) cover the same cells as
  // often: their instants differ completely, their coverage not at all.
  const Coverage first = coverageOf({outline({1, 0}), outline({0, 1})});
  const Coverage second = coverageOf({outline({0, 1}), outline({1, 0})});
  EXPECT_DOUBLE_EQ(coverageDistance(first, second), 0.0);
  ASSERT_EQ(first.fraction.size(), 2u);
  EXPECT_DOUBLE_EQ(first.fraction[0], 0.5);
  EXPECT_EQ(first.coveredCells, 2u);  // one cell in each of the two outlines
  // Half the time against always: |½ − 1| / max(½, 1) per cell.
  const Coverage always = coverageOf({outline({1, 1}), outline({1, 1})});
  EXPECT_DOUBLE_EQ(coverageDistance(first, always), 0.5);
  // Outlines of another grid are not comparable: the largest distance.
  EXPECT_DOUBLE_EQ(coverageDistance(first, coverageOf({outline({1, 1, 1})})), 1.0);
}

TEST(ClothStatistics, PooledStrainsGiveThePercentilesOfEveryEdgeAtEverySample) {
  GridSettings grid;
  grid.columns = 5;
  grid.rows = 4;
  const ClothModel model = ClothModel::grid(grid).value();
  // The rest shape and the same shape scaled by 1.1 about the origin: half the pooled edges at
  // strain 0, half at 0.1.
  const Vec3Array rest = model.restPositions();
  Vec3Array stretched = rest;
  for (Vec3& x : stretched) x *= 1.1;
  std::vector<Real> strains;
  appendEdgeStrains(model, rest, strains);
  ASSERT_EQ(strains.size(), model.edges().size());
  appendEdgeStrains(model, stretched, strains);
  ASSERT_EQ(strains.size(), 2 * model.edges().size());
  const StrainPercentiles pooled = strainPercentiles(strains);
  EXPECT_NEAR(pooled[0], 0.1, 1e-12);  // the median is the first of the stretched half
  EXPECT_NEAR(pooled[1], 0.1, 1e-12);
  EXPECT_NEAR(pooled[3], 0.1, 1e-12);
  std::vector<Real> restOnly;
  appendEdgeStrains(model, rest, restOnly);
  EXPECT_NEAR(strainPercentiles(restOnly)[3], 0.0, 1e-12);
}

TEST(ClothStatistics, PercentilesReadTheSortedStrains) {
  std::vector<Real> strains;
  for (int k = 99; k >= 0; --k) strains.push_back(Real(k) / 100);
  const StrainPercentiles percentiles = strainPercentiles(strains);
  EXPECT_DOUBLE_EQ(percentiles[0], 0.50);
  EXPECT_DOUBLE_EQ(percentiles[1], 0.90);
  EXPECT_DOUBLE_EQ(percentiles[2], 0.99);
  EXPECT_DOUBLE_EQ(percentiles[3], 0.99);
  std::vector<Real> none;
  EXPECT_EQ(strainPercentiles(none), (StrainPercentiles{0, 0, 0, 0}));
}

}  // namespace
}  // namespace weft
