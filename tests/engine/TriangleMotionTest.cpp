// The triangle-pair test of the feature pairs (engine/src/contact/FeaturePairs.h) alone: a pair
// it dismisses never comes within the margin over the step, in distance or along every axis at
// once (both sampled along the step), pairs moving together are dismissed however far they
// travel, and grid neighbours across a diagonal, whose boxes overlap, are dismissed.
#include "contact/FeaturePairs.h"

#include <weft/collision/Proximity.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace weft {
namespace {

using Corners = std::array<Vec3, 3>;

Corners moved(const Corners& corners, const Vec3& shift) {
  return {corners[0] + shift, corners[1] + shift, corners[2] + shift};
}

bool dismissed(const Corners& startA, const Corners& endA, const Corners& startB,
               const Corners& endB, Real margin) {
  return !trianglesMayComeWithin(triangleMotion(startA, endA), startA, triangleMotion(startB, endB),
                                 startB, margin);
}

// The least distance of the two triangles at `samples` + 1 times of the straight-line step.
Real closestOverTheStep(const Corners& startA, const Corners& endA, const Corners& startB,
                        const Corners& endB, int samples) {
  Real closest = std::numeric_limits<Real>::infinity();
  for (int s = 0; s <= samples; ++s) {
    const Real t = Real(s) / samples;
    Corners a, b;
    for (int k = 0; k < 3; ++k) {
      a[k] = startA[k] + t * (endA[k] - startA[k]);
      b[k] = startB[k] + t * (endB[k] - startB[k]);
    }
    // The distance of two triangles is reached at a vertex of one against the other, or between
    // two edges.
    for (int k = 0; k < 3; ++k) {
      closest = std::min(closest, closestPointOnTriangle(a[k], b[0], b[1], b[2]).distance);
      closest = std::min(closest, closestPointOnTriangle(b[k], a[0], a[1], a[2]).distance);
      for (int j = 0; j < 3; ++j) {
        closest = std::min(closest, closestPointsOnSegments(a[k], a[(k + 1) % 3], b[j],
                                                            b[(j + 1) % 3]).distance);
      }
    }
  }
  return closest;
}

// The least distance along every axis at once (max over the axes of the coordinate gap) of
// points sampled on the two triangles at `samples` + 1 times: at least their true such distance.
Real closestAlongEveryAxis(const Corners& startA, const Corners& endA, const Corners& startB,
                           const Corners& endB, int samples) {
  constexpr int kSteps = 6;  // barycentric grid of 28 points a triangle
  Real closest = std::numeric_limits<Real>::infinity();
  for (int s = 0; s <= samples; ++s) {
    const Real t = Real(s) / samples;
    std::vector<Vec3> pointsA, pointsB;
    for (int i = 0; i <= kSteps; ++i) {
      for (int j = 0; i + j <= kSteps; ++j) {
        const Real u = Real(i) / kSteps, w = Real(j) / kSteps;
        const auto at = [&](const Corners& start, const Corners& end) -> Vec3 {
          Vec3 point = Vec3::Zero();
          const Real weights[3] = {1 - u - w, u, w};
          for (int k = 0; k < 3; ++k) point += weights[k] * (start[k] + t * (end[k] - start[k]));
          return point;
        };
        pointsA.push_back(at(startA, endA));
        pointsB.push_back(at(startB, endB));
      }
    }
    for (const Vec3& a : pointsA) {
      for (const Vec3& b : pointsB) closest = std::min(closest, (a - b).cwiseAbs().maxCoeff());
    }
  }
  return closest;
}

TEST(TriangleMotion, IsTheMeanMoveAndTheLargestDeparture) {
  const Corners start{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const Corners end{Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(1, 1, 0.3)};
  const TriangleMotion motion = triangleMotion(start, end);
  EXPECT_TRUE(motion.centroid.isApprox(Vec3(1.0 / 3, 1.0 / 3, 0)));
  EXPECT_TRUE(motion.shift.isApprox(Vec3(1, 0, 0.1)));
  EXPECT_NEAR(motion.spread, 0.2, 1e-12);
}

TEST(TriangleMotion, APairMovingTogetherIsDismissedHoweverFarItTravels) {
  const Corners a{Vec3(0, 0, 0), Vec3(0.05, 0, 0), Vec3(0, 0.05, 0)};
  const Corners b = moved(a, Vec3(0.2, 0, 0));
  const Vec3 travel(3.0, -2.0, 1.0);  // 3.7 m in one step, both triangles alike
  EXPECT_TRUE(dismissed(a, moved(a, travel), b, moved(b, travel), 0.006));
  // Closing the 15 cm gap between them is not dismissed.
  EXPECT_FALSE(dismissed(a, a, b, moved(b, Vec3(-0.16, 0, 0)), 0.006));
}

TEST(TriangleMotion, GridNeighboursAcrossADiagonalAreDismissed) {
  // Cells of 5 cm split along the diagonal from (i, j) to (i + 1, j + 1). The upper triangle of
  // cell (0, 0) and the lower one of cell (1, 0) share no vertex and their boxes meet along
  // x = 5 cm, yet they are 3.5 cm apart (the corner (1, 1) against the diagonal of cell (1, 0)).
  const Real h = 0.05;
  const auto at = [h](Real i, Real j) { return Vec3(i * h, j * h, 0); };
  const Corners upper{at(0, 0), at(1, 1), at(0, 1)};
  const Corners lowerRight{at(1, 0), at(2, 0), at(2, 1)};
  EXPECT_TRUE(dismissed(upper, upper, lowerRight, lowerRight, 0.006));
  EXPECT_NEAR(closestOverTheStep(upper, upper, lowerRight, lowerRight, 1), h / std::sqrt(2.0), 1e-12);
  // The same pair swinging together by 2 cm, each corner 1 mm off the common motion.
  const Vec3 swing(0, 0, 0.02);
  const Corners upperEnd{upper[0] + swing, upper[1] + swing + Vec3(0, 0, 0.001), upper[2] + swing};
  EXPECT_TRUE(dismissed(upper, upperEnd, lowerRight, moved(lowerRight, swing), 0.006));
}

TEST(TriangleMotion, ADismissedPairNeverComesWithinTheMargin) {
  // Random triangles and motions: whenever the test dismisses a pair, the sampled distance over
  // the step stays beyond the margin. Pairs that do come close are never dismissed.
  std::mt19937 random(7);
  std::uniform_real_distribution<Real> unit(-1, 1);
  const auto point = [&](Real scale) -> Vec3 {
    return scale * Vec3(unit(random), unit(random), unit(random));
  };
  const Real margin = 0.006;
  int dismissedCount = 0, close = 0;
  for (int draw = 0; draw < 4000; ++draw) {
    const Vec3 offset = point(0.12);
    const Corners startA{point(0.05), point(0.05), point(0.05)};
    const Corners startB{offset + point(0.05), offset + point(0.05), offset + point(0.05)};
    const Vec3 common = point(1.0);
    const Corners endA{startA[0] + common + point(0.03), startA[1] + common + point(0.03),
                       startA[2] + common + point(0.03)};
    const Corners endB{startB[0] + common + point(0.03), startB[1] + common + point(0.03),
                       startB[2] + common + point(0.03)};
    const Real closest = closestOverTheStep(startA, endA, startB, endB, 64);
    close += closest <= margin;
    if (dismissed(startA, endA, startB, endB, margin)) {
      ++dismissedCount;
      EXPECT_GT(closest, margin) << "draw " << draw;
      // Also apart along some axis at every time (what the impact pass relies on when it reuses
      // the detection's pairs).
      EXPECT_GT(closestAlongEveryAxis(startA, endA, startB, endB, 8), margin) << "draw " << draw;
    }
  }
  // The draws hold both kinds.
  EXPECT_GT(dismissedCount, 100);
  EXPECT_GT(close, 100);
}

}  // namespace
}  // namespace weft
