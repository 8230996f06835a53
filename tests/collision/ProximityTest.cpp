// Closest-point kernels against brute-force sampling, and their feature (vertex/edge/face) and
// parallel-segment behaviour.
#include <weft/collision/Proximity.h>

#include <gtest/gtest.h>

#include <random>

namespace weft {
namespace {

Vec3 randomPoint(std::mt19937& random, Real extent) {
  std::uniform_real_distribution<Real> coordinate(-extent, extent);
  return Vec3(coordinate(random), coordinate(random), coordinate(random));
}

// min over a barycentric lattice of |p − x|: an upper bound on the true distance that is within
// (longest edge / resolution) of it.
Real sampledTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                             int resolution) {
  Real best = std::numeric_limits<Real>::infinity();
  for (int i = 0; i <= resolution; ++i) {
    for (int j = 0; i + j <= resolution; ++j) {
      const Real u = Real(i) / resolution, v = Real(j) / resolution;
      best = std::min(best, (p - ((1 - u - v) * a + u * b + v * c)).norm());
    }
  }
  return best;
}

TEST(ClosestPointOnTriangle, MatchesSamplingOnRandomTriangles) {
  std::mt19937 random(1);
  const int resolution = 200;
  for (int trial = 0; trial < 200; ++trial) {
    const Vec3 a = randomPoint(random, 1), b = randomPoint(random, 1), c = randomPoint(random, 1);
    const Vec3 p = randomPoint(random, 2);
    const TriangleClosestPoint result = closestPointOnTriangle(p, a, b, c);
    const Vec3& w = result.barycentric;
    // A point of the triangle, consistent with the weights and the distance.
    EXPECT_GE(w.minCoeff(), 0);
    EXPECT_NEAR(w.sum(), 1, 1e-12);
    EXPECT_LT((result.point - (w[0] * a + w[1] * b + w[2] * c)).norm(), 1e-12);
    EXPECT_NEAR(result.distance, (p - result.point).norm(), 1e-12);
    // No sample is closer; the nearest sample is within the lattice spacing.
    const Real longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const Real sampled = sampledTriangleDistance(p, a, b, c, resolution);
    EXPECT_LE(result.distance, sampled + 1e-12) << "trial " << trial;
    EXPECT_GE(result.distance, sampled - longest / resolution) << "trial " << trial;
  }
}

TEST(ClosestPointOnTriangle, ReportsFeaturesWithExactWeights) {
  const Vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  // Face: above the interior.
  TriangleClosestPoint r = closestPointOnTriangle(Vec3(0.5, 0.5, 3), a, b, c);
  EXPECT_NEAR(r.distance, 3, 1e-15);
  EXPECT_NEAR(r.barycentric[1], 0.25, 1e-15);
  EXPECT_NEAR(r.barycentric[2], 0.25, 1e-15);
  // Vertex b: weight exactly 1, point exactly b.
  r = closestPointOnTriangle(Vec3(3, -1, 1), a, b, c);
  EXPECT_EQ(r.barycentric, Vec3(0, 1, 0));
  EXPECT_EQ(r.point, b);
  EXPECT_NEAR(r.distance, std::sqrt(3.0), 1e-15);
  // Edge bc: the weight of a exactly 0.
  r = closestPointOnTriangle(Vec3(2, 2, 0), a, b, c);
  EXPECT_EQ(r.barycentric[0], 0);
  EXPECT_NEAR(r.barycentric[1], 0.5, 1e-15);
  EXPECT_NEAR(r.distance, std::sqrt(2.0), 1e-15);
  // Edge ab (below the x axis): the weight of c exactly 0.
  r = closestPointOnTriangle(Vec3(1, -1, 0), a, b, c);
  EXPECT_EQ(r.barycentric[2], 0);
  EXPECT_EQ(r.point, Vec3(1, 0, 0));
}

TEST(ClosestPointOnTriangle, DegenerateTriangleFallsBackToItsEdges) {
  // Collinear corners: the closest point of the segment they span.
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(3, 0, 0);
  const TriangleClosestPoint r = closestPointOnTriangle(Vec3(2, 1, 0), a, b, c);
  EXPECT_NEAR(r.distance, 1, 1e-15);
  EXPECT_LT((r.point - Vec3(2, 0, 0)).norm(), 1e-15);
  EXPECT_NEAR(r.barycentric.sum(), 1, 1e-15);
}

TEST(ClosestPointsOnSegments, MatchesSamplingOnRandomSegments) {
  std::mt19937 random(2);
  const int resolution = 300;
  for (int trial = 0; trial < 120; ++trial) {
    const Vec3 p0 = randomPoint(random, 1), p1 = randomPoint(random, 1);
    const Vec3 q0 = randomPoint(random, 1), q1 = randomPoint(random, 1);
    const SegmentClosestPoints r = closestPointsOnSegments(p0, p1, q0, q1);
    EXPECT_GE(r.firstParameter, 0);
    EXPECT_LE(r.firstParameter, 1);
    EXPECT_GE(r.secondParameter, 0);
    EXPECT_LE(r.secondParameter, 1);
    EXPECT_LT((r.pointOnFirst - (p0 + r.firstParameter * (p1 - p0))).norm(), 1e-14);
    EXPECT_LT((r.pointOnSecond - (q0 + r.secondParameter * (q1 - q0))).norm(), 1e-14);
    Real sampled = std::numeric_limits<Real>::infinity();
    for (int i = 0; i <= resolution; ++i) {
      for (int j = 0; j <= resolution; ++j) {
        const Vec3 x = p0 + (Real(i) / resolution) * (p1 - p0);
        const Vec3 y = q0 + (Real(j) / resolution) * (q1 - q0);
        sampled = std::min(sampled, (x - y).norm());
      }
    }
    const Real spacing = ((p1 - p0).norm() + (q1 - q0).norm()) / resolution;
    EXPECT_LE(r.distance, sampled + 1e-12) << "trial " << trial;
    EXPECT_GE(r.distance, sampled - spacing) << "trial " << trial;
  }
}

TEST(ClosestPointsOnSegments, ParallelOverlappingSegmentsMeetInTheMiddleOfTheOverlap) {
  // Overlap of x ∈ [1, 2]: the middle is x = 1.5, at distance 0.5 exactly.
  const SegmentClosestPoints r =
      closestPointsOnSegments(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0.5, 0), Vec3(3, 0.5, 0));
  EXPECT_NEAR(r.distance, 0.5, 1e-15);
  EXPECT_NEAR(r.pointOnFirst.x(), 1.5, 1e-15);
  EXPECT_NEAR(r.pointOnSecond.x(), 1.5, 1e-15);
  // Anti-parallel and a rotation by 1e-9 rad: the same answer within 1e-8.
  const SegmentClosestPoints rotated = closestPointsOnSegments(
      Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(3, 0.5, 0), Vec3(1, 0.5 + 2e-9, 0));
  EXPECT_NEAR(rotated.pointOnFirst.x(), 1.5, 1e-8);
  EXPECT_NEAR(rotated.distance, 0.5, 1e-8);
}

TEST(ClosestPointsOnSegments, ParallelDisjointAndZeroLengthSegments) {
  // Collinear, disjoint: nearest ends.
  SegmentClosestPoints r =
      closestPointsOnSegments(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(3, 0, 0), Vec3(5, 0, 0));
  EXPECT_EQ(r.firstParameter, 1);
  EXPECT_EQ(r.secondParameter, 0);
  EXPECT_NEAR(r.distance, 2, 1e-15);
  // A point against a segment.
  r = closestPointsOnSegments(Vec3(1, 1, 0), Vec3(1, 1, 0), Vec3(0, 0, 0), Vec3(2, 0, 0));
  EXPECT_NEAR(r.secondParameter, 0.5, 1e-15);
  EXPECT_NEAR(r.distance, 1, 1e-15);
  // Two points.
  r = closestPointsOnSegments(Vec3(1, 1, 0), Vec3(1, 1, 0), Vec3(1, 1, 2), Vec3(1, 1, 2));
  EXPECT_NEAR(r.distance, 2, 1e-15);
}

TEST(ClosestPointsOnSegmentAndTriangle, MatchesSamplingOnRandomPairs) {
  std::mt19937 random(3);
  const int resolution = 60;
  int crossings = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a = randomPoint(random, 1), b = randomPoint(random, 1), c = randomPoint(random, 1);
    const Vec3 p0 = randomPoint(random, 1.5), p1 = randomPoint(random, 1.5);
    const SegmentTriangleClosestPoints result = closestPointsOnSegmentAndTriangle(p0, p1, a, b, c);
    const Vec3& w = result.barycentric;
    EXPECT_GE(w.minCoeff(), 0);
    EXPECT_NEAR(w.sum(), 1, 1e-12);
    EXPECT_GE(result.segmentParameter, 0);
    EXPECT_LE(result.segmentParameter, 1);
    EXPECT_LT((result.pointOnTriangle - (w[0] * a + w[1] * b + w[2] * c)).norm(), 1e-12);
    EXPECT_LT((result.pointOnSegment - (p0 + result.segmentParameter * (p1 - p0))).norm(), 1e-12);
    EXPECT_NEAR(result.distance, (result.pointOnSegment - result.pointOnTriangle).norm(), 1e-12);
    // Sampling the segment and the triangle finds nothing closer, and something within the
    // spacing of the two lattices.
    Real sampled = std::numeric_limits<Real>::infinity();
    for (int k = 0; k <= resolution; ++k) {
      const Vec3 p = p0 + (Real(k) / resolution) * (p1 - p0);
      sampled = std::min(sampled, sampledTriangleDistance(p, a, b, c, resolution));
    }
    const Real longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    EXPECT_LE(result.distance, sampled + 1e-12) << "trial " << trial;
    EXPECT_GE(result.distance, sampled - (longest + (p1 - p0).norm()) / resolution) << "trial " << trial;
    if (result.distance == 0) ++crossings;
  }
  EXPECT_GT(crossings, 10);  // the crossing branch was exercised
}

TEST(ClosestPointsOnSegmentAndTriangle, CrossingPointsAndZeroLengthSegments) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Straight through the face at (0.25, 0.25): distance 0 there, at the segment's middle.
  const SegmentTriangleClosestPoints through =
      closestPointsOnSegmentAndTriangle(Vec3(0.25, 0.25, -1), Vec3(0.25, 0.25, 1), a, b, c);
  EXPECT_EQ(through.distance, 0);
  EXPECT_NEAR(through.segmentParameter, 0.5, 1e-15);
  EXPECT_LT((through.barycentric - Vec3(0.5, 0.25, 0.25)).norm(), 1e-15);
  // Past the hypotenuse: the closest pair is the segment's point above the edge bc's middle.
  const SegmentTriangleClosestPoints beside =
      closestPointsOnSegmentAndTriangle(Vec3(1, 1, -1), Vec3(1, 1, 1), a, b, c);
  EXPECT_NEAR(beside.distance, std::sqrt(0.5), 1e-15);
  EXPECT_LT((beside.barycentric - Vec3(0, 0.5, 0.5)).norm(), 1e-15);
  // A point (a sphere's centre) above the face.
  const SegmentTriangleClosestPoints point =
      closestPointsOnSegmentAndTriangle(Vec3(0.2, 0.3, 0.5), Vec3(0.2, 0.3, 0.5), a, b, c);
  EXPECT_NEAR(point.distance, 0.5, 1e-15);
  EXPECT_LT((point.pointOnTriangle - Vec3(0.2, 0.3, 0)).norm(), 1e-15);
  // Parallel to the face above it: every point is at the same height.
  const SegmentTriangleClosestPoints parallel =
      closestPointsOnSegmentAndTriangle(Vec3(0.1, 0.1, 0.3), Vec3(0.2, 0.1, 0.3), a, b, c);
  EXPECT_NEAR(parallel.distance, 0.3, 1e-15);
}

}  // namespace
}  // namespace weft
