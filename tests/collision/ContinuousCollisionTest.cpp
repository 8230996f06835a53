// Continuous collision: the root finder alone, then vertex–triangle and edge–edge sweeps on
// constructed cases with known contact times, degenerate motions, near misses, and random
// motions built to cross at a known time.
#include <weft/collision/ContinuousCollision.h>

#include <weft/collision/Proximity.h>

#include "CoplanarityCubic.h"

#include <gtest/gtest.h>

#include <random>

namespace weft {
namespace {

using detail::CandidateTimes;
using detail::Cubic;

bool hasTimeNear(const CandidateTimes& candidates, Real t, Real tolerance) {
  for (int i = 0; i < candidates.count; ++i) {
    if (std::abs(candidates.times[i] - t) <= tolerance) return true;
  }
  return false;
}

// ---- root finder ---------------------------------------------------------------------------

TEST(CoplanarityCubic, FindsThreeSimpleRoots) {
  // (t − 0.3)(t − 0.5)(t − 0.9) = t³ − 1.7 t² + 0.87 t − 0.135
  const Cubic f{-0.135, 0.87, -1.7, 1.0};
  const CandidateTimes candidates = detail::cubicCandidateTimes(f, 1e-15);
  EXPECT_TRUE(hasTimeNear(candidates, 0.3, 1e-12));
  EXPECT_TRUE(hasTimeNear(candidates, 0.5, 1e-12));
  EXPECT_TRUE(hasTimeNear(candidates, 0.9, 1e-12));
  EXPECT_EQ(candidates.count, 3);
  for (int i = 0; i + 1 < candidates.count; ++i) {
    EXPECT_LT(candidates.times[i], candidates.times[i + 1]);
  }
}

TEST(CoplanarityCubic, HandlesDoubleRootsLinearAndConstantCases) {
  // (t − 0.5)²: touches zero without a sign change.
  EXPECT_TRUE(hasTimeNear(detail::cubicCandidateTimes(Cubic{0.25, -1, 1, 0}, 1e-15), 0.5, 1e-12));
  // Linear t − 0.25.
  const CandidateTimes linear = detail::cubicCandidateTimes(Cubic{-0.25, 1, 0, 0}, 1e-15);
  EXPECT_EQ(linear.count, 1);
  EXPECT_TRUE(hasTimeNear(linear, 0.25, 1e-12));
  // A constant far from zero: nothing. Roots outside [0, 1]: nothing.
  EXPECT_EQ(detail::cubicCandidateTimes(Cubic{1, 0, 0, 0}, 1e-15).count, 0);
  EXPECT_EQ(detail::cubicCandidateTimes(Cubic{-2.0, 1, 0, 0}, 1e-15).count, 0);
  // A root exactly at t = 1 and one at t = 0.
  EXPECT_TRUE(hasTimeNear(detail::cubicCandidateTimes(Cubic{-1, 1, 0, 0}, 1e-15), 1.0, 0));
  EXPECT_TRUE(hasTimeNear(detail::cubicCandidateTimes(Cubic{0, 1, 0, 0}, 1e-15), 0.0, 0));
}

TEST(CoplanarityCubic, ACubicThatComesWithinTheSlackOfZeroAlwaysHasACandidate) {
  // Random cubics, many of them grazing zero on [0, 1] (a dip placed at a random time): whenever
  // a fine sampling finds |f| within the slack or a change of sign, there must be candidates;
  // the Bernstein bound that skips the rest may never skip one of these.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<Real> coefficient(-1, 1), time(0, 1);
  const Real slack = 1e-6;
  int grazing = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // f(t) = a (t − r)² (t − s) + d, with d small so that many cubics pass close to zero.
    const Real a = coefficient(random), r = time(random), s = 1 + 2 * time(random);
    const Real d = 1e-3 * coefficient(random);
    const Cubic f{-a * r * r * s + d, a * (r * r + 2 * r * s), -a * (2 * r + s), a};
    bool touches = false;
    for (int k = 0; k <= 4000 && !touches; ++k) {
      const Real t = k / 4000.0;
      touches = std::abs(f(t)) <= slack || (k > 0 && (f(t) < 0) != (f((k - 1) / 4000.0) < 0));
    }
    grazing += touches;
    if (touches) {
      EXPECT_GT(detail::cubicCandidateTimes(f, slack).count, 0)
          << "f = " << f.c0 << " + " << f.c1 << " t + " << f.c2 << " t² + " << f.c3 << " t³";
    }
  }
  EXPECT_GT(grazing, 1000);  // the draw exercises the case it is about
}

TEST(CoplanarityCubic, ReportsTheLeftEndOfTheBracket) {
  // The reported time is never after the crossing.
  const Real root = 1.0 / 3.0;
  const CandidateTimes candidates = detail::cubicCandidateTimes(Cubic{-root, 1, 0, 0}, 0);
  ASSERT_EQ(candidates.count, 1);
  EXPECT_LE(candidates.times[0], root);
  EXPECT_GT(candidates.times[0], root - 1e-12);
}

// The candidates of the definition: the pieces between the turning points, every sign change
// bisected by halving until the bracket is narrower than 1e-13, its left end reported (without
// the root finder's shortcut for a cubic that stays clear of zero, which finds nothing there).
CandidateTimes bisectedCandidates(const Cubic& f, Real slack) {
  CandidateTimes breaks;
  detail::addQuadraticRootsAndVertex(f.c1, 2 * f.c2, 3 * f.c3, breaks);
  breaks.add(0);
  breaks.add(1);
  breaks.sort();
  CandidateTimes candidates;
  for (int piece = 0; piece + 1 < breaks.count; ++piece) {
    const Real low = breaks.times[piece], high = breaks.times[piece + 1];
    const Real fLow = f(low), fHigh = f(high);
    if (std::abs(fLow) <= slack) candidates.add(low);
    if (!((fLow < 0 && fHigh > 0) || (fLow > 0 && fHigh < 0))) continue;
    Real left = low, right = high;
    for (int step = 0; step < 64 && right - left > 1e-13; ++step) {
      const Real middle = 0.5 * (left + right);
      const Real fMiddle = f(middle);
      if (fMiddle == 0) {
        left = middle;
        break;
      }
      ((fMiddle < 0) == (fLow < 0) ? left : right) = middle;
    }
    candidates.add(left);
  }
  if (std::abs(f(1)) <= slack) candidates.add(1);
  candidates.sort();
  return candidates;
}

TEST(CoplanarityCubic, ReportsEveryCrossingAtMost1e13BeforeItAndNeverAfter) {
  // Against plain bisection to a bracket of 1e-13 on simple, clustered, double and nearly triple
  // roots, at scales from 1e-30 to 1e30: the same crossings, each reported within 2e-13 of
  // bisection's time.
  std::mt19937_64 random(11);
  std::uniform_real_distribution<Real> unit(0, 1), symmetric(-1, 1);
  int crossings = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const Real r = unit(random), scale = std::pow(10.0, 60 * unit(random) - 30);
    Real s = 0, u = 0;
    switch (trial % 5) {
      case 0: s = unit(random), u = unit(random); break;                 // three roots
      case 1: s = r + 1e-9 * symmetric(random), u = unit(random); break;  // a close pair
      case 2: s = r, u = r + 1e-6 * symmetric(random); break;             // clustered three
      case 3: s = r, u = 1 + unit(random); break;                         // a double root
      default: s = r + 1e-12 * symmetric(random), u = r; break;           // nearly triple
    }
    // scale (t − r)(t − s)(t − u) + a small shift, so that roots move off their cluster.
    const Real shift = (trial % 3 == 0 ? 0 : 1e-12 * symmetric(random));
    const Cubic f{scale * (-r * s * u + shift), scale * (r * s + r * u + s * u),
                  scale * -(r + s + u), scale};
    const CandidateTimes found = detail::cubicCandidateTimes(f, 0);
    const CandidateTimes plain = bisectedCandidates(f, 0);
    ASSERT_EQ(found.count, plain.count) << "trial " << trial;
    for (int i = 0; i < plain.count; ++i) {
      ASSERT_NEAR(found.times[i], plain.times[i], 2e-13) << "trial " << trial << ", root " << i;
    }
    crossings += plain.count;
  }
  EXPECT_GT(crossings, 200000);  // most draws have roots in [0, 1] to compare
}

TEST(CoplanarityCubic, ReportsASignChangeBeforeTheCrossingInExactArithmetic) {
  // f = scale (t − r) for roots r that no double holds exactly: the reported time is below the
  // true root, by at most 1e-13.
  std::mt19937_64 random(5);
  std::uniform_real_distribution<Real> unit(0.01, 0.99);
  for (int trial = 0; trial < 10000; ++trial) {
    const Real r = unit(random), scale = std::pow(10.0, 20 * unit(random) - 10);
    const Cubic f{-scale * r, scale, 0, 0};  // the rounding of −scale r moves the root by ~1e-17
    const Real root = -f.c0 / f.c1;
    const CandidateTimes found = detail::cubicCandidateTimes(f, 0);
    ASSERT_EQ(found.count, 1);
    EXPECT_LE(found.times[0], root);
    EXPECT_GT(found.times[0], root - 1e-13);
  }
}

// ---- vertex–triangle -----------------------------------------------------------------------

const std::array<Vec3, 3> kTriangle = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};

std::optional<VertexTriangleImpact> sweepThroughStaticTriangle(const Vec3& from, const Vec3& to) {
  return sweptVertexTriangle(from, to, kTriangle, kTriangle);
}

TEST(SweptVertexTriangle, VertexFallingThroughTheFace) {
  const auto impact = sweepThroughStaticTriangle(Vec3(0.25, 0.25, 1), Vec3(0.25, 0.25, -1));
  ASSERT_TRUE(impact);
  EXPECT_NEAR(impact->time, 0.5, 1e-12);
  EXPECT_NEAR(impact->barycentric[0], 0.5, 1e-12);
  EXPECT_NEAR(impact->barycentric[1], 0.25, 1e-12);
  EXPECT_NEAR(impact->barycentric[2], 0.25, 1e-12);
  EXPECT_LT((impact->normal - Vec3(0, 0, 1)).norm(), 1e-12);  // the vertex came from +z
  EXPECT_LE(impact->distance, kDefaultContactTolerance);
  // From below: the normal flips.
  const auto fromBelow = sweepThroughStaticTriangle(Vec3(0.25, 0.25, -1), Vec3(0.25, 0.25, 3));
  ASSERT_TRUE(fromBelow);
  EXPECT_NEAR(fromBelow->time, 0.25, 1e-12);
  EXPECT_LT((fromBelow->normal - Vec3(0, 0, -1)).norm(), 1e-12);
}

TEST(SweptVertexTriangle, TriangleMovingOntoAStillVertex) {
  std::array<Vec3, 3> end = kTriangle;
  for (Vec3& x : end) x.z() += 2;
  const auto impact = sweptVertexTriangle(Vec3(0.2, 0.3, 1), Vec3(0.2, 0.3, 1), kTriangle, end);
  ASSERT_TRUE(impact);
  EXPECT_NEAR(impact->time, 0.5, 1e-12);
  EXPECT_LT((impact->normal - Vec3(0, 0, 1)).norm(), 1e-12);
}

TEST(SweptVertexTriangle, FarFromTheOriginGivesTheSameTime) {
  const Vec3 offset(1000, -2000, 500);
  std::array<Vec3, 3> shifted = kTriangle;
  for (Vec3& x : shifted) x += offset;
  const auto impact = sweptVertexTriangle(Vec3(0.25, 0.25, 1) + offset,
                                          Vec3(0.25, 0.25, -1) + offset, shifted, shifted);
  ASSERT_TRUE(impact);
  EXPECT_NEAR(impact->time, 0.5, 1e-9);
}

TEST(SweptVertexTriangle, CrossingExactlyThroughAnEdgeOrACorner) {
  const auto onEdge = sweepThroughStaticTriangle(Vec3(0.5, 0, 1), Vec3(0.5, 0, -1));
  ASSERT_TRUE(onEdge);
  EXPECT_NEAR(onEdge->time, 0.5, 1e-12);
  EXPECT_EQ(onEdge->barycentric[2], 0);
  const auto onCorner = sweepThroughStaticTriangle(Vec3(1, 0, 1), Vec3(1, 0, -3));
  ASSERT_TRUE(onCorner);
  EXPECT_NEAR(onCorner->time, 0.25, 1e-12);
  EXPECT_EQ(onCorner->barycentric, Vec3(0, 1, 0));
}

TEST(SweptVertexTriangle, NearMissesReportNothing) {
  // Through the plane 1e-4 beside edge ab (y = 0), beside edge bc (x + y = 1), beside a corner.
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(0.5, -1e-4, 1), Vec3(0.5, -1e-4, -1)));
  const Real beside = 0.5 + 1e-4 / std::sqrt(2.0);
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(beside, beside, 1), Vec3(beside, beside, -1)));
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(-1e-4, -1e-4, 1), Vec3(-1e-4, -1e-4, -1)));
  // Stopping 1e-4 above the face.
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(0.25, 0.25, 1), Vec3(0.25, 0.25, 1e-4)));
}

TEST(SweptVertexTriangle, TouchingExactlyAtTheEndOfTheStep) {
  const auto impact = sweepThroughStaticTriangle(Vec3(0.25, 0.25, 1), Vec3(0.25, 0.25, 0));
  ASSERT_TRUE(impact);
  EXPECT_EQ(impact->time, 1.0);
  EXPECT_LT((impact->normal - Vec3(0, 0, 1)).norm(), 1e-12);
}

TEST(SweptVertexTriangle, MotionParallelToTheFace) {
  // Above the face, sliding across it: never coplanar.
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(-1, 0.25, 0.5), Vec3(2, 0.25, 0.5)));
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(-1, 0.25, 1e-4), Vec3(2, 0.25, 1e-4)));
  // In the plane, sliding into the triangle from x = −1: enters at x = 0, t = 1 / 1.25.
  const auto inPlane = sweepThroughStaticTriangle(Vec3(-1, 0.25, 0), Vec3(0.25, 0.25, 0));
  ASSERT_TRUE(inPlane);
  EXPECT_NEAR(inPlane->time, 0.8, 1e-9);
  EXPECT_NEAR(inPlane->barycentric[1], 0, 1e-9);
  EXPECT_NEAR(inPlane->normal.z(), inPlane->normal.z() > 0 ? 1 : -1, 1e-12);
  // In the plane but beside the triangle the whole time.
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(-1, 2, 0), Vec3(2, 2, 0)));
}

TEST(SweptVertexTriangle, AlreadyCoplanarAtTheStart) {
  // Inside the face at t = 0, leaving upward: contact at t = 0.
  const auto inside = sweepThroughStaticTriangle(Vec3(0.25, 0.25, 0), Vec3(0.25, 0.25, 1));
  ASSERT_TRUE(inside);
  EXPECT_EQ(inside->time, 0.0);
  EXPECT_LT((inside->normal - Vec3(0, 0, -1)).norm(), 1e-12)
      << "leaving toward +z means arriving from −z: the normal faces −z";
  // In the plane but outside the triangle at t = 0, leaving: nothing.
  EXPECT_FALSE(sweepThroughStaticTriangle(Vec3(2, 2, 0), Vec3(2, 2, 1)));
}

// Random motions built so that the vertex is inside the triangle at a known time t*: the sweep
// must report a contact no later than t*, and the reported contact must be real.
TEST(SweptVertexTriangle, FindsConstructedCrossingsOfRandomMotions) {
  std::mt19937 random(9);
  std::uniform_real_distribution<Real> coordinate(-1, 1);
  std::uniform_real_distribution<Real> unit(0.05, 0.95);
  auto point = [&]() { return Vec3(coordinate(random), coordinate(random), coordinate(random)); };
  for (int trial = 0; trial < 2000; ++trial) {
    const std::array<Vec3, 3> start = {point(), point(), point()};
    const std::array<Vec3, 3> end = {point(), point(), point()};
    const Real crossing = unit(random);
    Real w1 = unit(random), w2 = unit(random);
    if (w1 + w2 > 0.95) {
      w1 *= 0.5;
      w2 *= 0.5;
    }
    auto at = [&](int k, Real t) { return Vec3(start[k] + t * (end[k] - start[k])); };
    const Vec3 target = (1 - w1 - w2) * at(0, crossing) + w1 * at(1, crossing) + w2 * at(2, crossing);
    const Vec3 vertexStart = point();
    const Vec3 vertexEnd = vertexStart + (target - vertexStart) / crossing;
    const auto impact = sweptVertexTriangle(vertexStart, vertexEnd, start, end);
    ASSERT_TRUE(impact) << "trial " << trial;
    EXPECT_LE(impact->time, crossing + 1e-9) << "trial " << trial;
    const Real t = impact->time;
    const Vec3 vertex = vertexStart + t * (vertexEnd - vertexStart);
    EXPECT_LE(closestPointOnTriangle(vertex, at(0, t), at(1, t), at(2, t)).distance, 1e-6)
        << "trial " << trial;
  }
}

// ---- edge–edge -----------------------------------------------------------------------------

using Edge = std::array<Vec3, 2>;

Edge shifted(const Edge& edge, const Vec3& offset) { return {edge[0] + offset, edge[1] + offset}; }

TEST(SweptEdgeEdge, TwoEdgesCrossing) {
  const Edge first = {Vec3(-1, 0, 1), Vec3(1, 0, 1)};
  const Edge second = {Vec3(0, -1, 0), Vec3(0, 1, 0)};
  const auto impact = sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -2)), second, second);
  ASSERT_TRUE(impact);
  EXPECT_NEAR(impact->time, 0.5, 1e-12);
  EXPECT_NEAR(impact->firstParameter, 0.5, 1e-12);
  EXPECT_NEAR(impact->secondParameter, 0.5, 1e-12);
  EXPECT_LT((impact->normal - Vec3(0, 0, 1)).norm(), 1e-12);  // toward where the first came from
  // Both moving: the second rises while the first falls; 1 − 2t = t at t = 1/3.
  const auto both = sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -2)), second,
                                  shifted(second, Vec3(0, 0, 1)));
  ASSERT_TRUE(both);
  EXPECT_NEAR(both->time, 1.0 / 3.0, 1e-12);
}

TEST(SweptEdgeEdge, NearMissesReportNothing) {
  // The first edge ends 1e-4 before the second edge's line.
  const Edge shortFirst = {Vec3(-1, 0, 1), Vec3(-1e-4, 0, 1)};
  const Edge second = {Vec3(0, -1, 0), Vec3(0, 1, 0)};
  EXPECT_FALSE(sweptEdgeEdge(shortFirst, shifted(shortFirst, Vec3(0, 0, -2)), second, second));
  // The second edge ends 1e-4 before the first edge's line.
  const Edge first = {Vec3(-1, 0, 1), Vec3(1, 0, 1)};
  const Edge shortSecond = {Vec3(0, 1e-4, 0), Vec3(0, 1, 0)};
  EXPECT_FALSE(sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -2)), shortSecond, shortSecond));
  // Stopping 1e-4 above.
  EXPECT_FALSE(sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -1 + 1e-4)), second, second));
}

TEST(SweptEdgeEdge, TouchingExactlyAtTheEndOfTheStep) {
  const Edge first = {Vec3(-1, 0, 1), Vec3(1, 0, 1)};
  const Edge second = {Vec3(0, -1, 0), Vec3(0, 1, 0)};
  const auto impact = sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -1)), second, second);
  ASSERT_TRUE(impact);
  EXPECT_EQ(impact->time, 1.0);
}

TEST(SweptEdgeEdge, ParallelEdgesFallingOntoEachOther) {
  // Both along x; they overlap on x ∈ [0.5, 1] when the first reaches z = 0 at t = 0.5.
  const Edge first = {Vec3(0, 0, 1), Vec3(1, 0, 1)};
  const Edge second = {Vec3(0.5, 0, 0), Vec3(1.5, 0, 0)};
  const auto impact = sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -2)), second, second);
  ASSERT_TRUE(impact);
  EXPECT_NEAR(impact->time, 0.5, 1e-9);
  EXPECT_NEAR(impact->firstParameter, 0.75, 1e-9);
  EXPECT_NEAR(impact->secondParameter, 0.25, 1e-9);
  EXPECT_LT((impact->normal - Vec3(0, 0, 1)).norm(), 1e-9);
  // The same 1e-4 to the side: nothing.
  const Edge beside = shifted(second, Vec3(0, 1e-4, 0));
  EXPECT_FALSE(sweptEdgeEdge(first, shifted(first, Vec3(0, 0, -2)), beside, beside));
  // Parallel, moving in their common plane toward each other: meet at t = 0.75.
  const Edge left = {Vec3(-1, 0, 0), Vec3(-1, 1, 0)};
  const Edge right = {Vec3(0.5, -1, 0), Vec3(0.5, 2, 0)};
  const auto sliding = sweptEdgeEdge(left, shifted(left, Vec3(2, 0, 0)), right, right);
  ASSERT_TRUE(sliding);
  EXPECT_NEAR(sliding->time, 0.75, 1e-9);
}

TEST(SweptEdgeEdge, CoplanarMotion) {
  // Already crossing at t = 0 in the plane z = 0.
  const Edge first = {Vec3(-1, 0, 0), Vec3(1, 0, 0)};
  const Edge second = {Vec3(0, -1, 0), Vec3(0, 1, 0)};
  const auto atStart = sweptEdgeEdge(first, shifted(first, Vec3(0, 0, 1)), second, second);
  ASSERT_TRUE(atStart);
  EXPECT_EQ(atStart->time, 0.0);
  // Coplanar throughout, not parallel: the first edge (along y) sweeps along x into the end of
  // the second (along x, starting at x = 0.5): contact at t = 0.75.
  const Edge sweeping = {Vec3(-1, 0, 0), Vec3(-1, 1, 0)};
  const Edge still = {Vec3(0.5, 0.5, 0), Vec3(2, 0.5, 0)};
  const auto inPlane = sweptEdgeEdge(sweeping, shifted(sweeping, Vec3(2, 0, 0)), still, still);
  ASSERT_TRUE(inPlane);
  EXPECT_NEAR(inPlane->time, 0.75, 1e-9);
  EXPECT_NEAR(inPlane->firstParameter, 0.5, 1e-9);
  EXPECT_NEAR(inPlane->secondParameter, 0, 1e-9);
  // Coplanar throughout, sweeping past the end of the other edge: nothing.
  const Edge past = {Vec3(0.5, 1.5, 0), Vec3(2, 1.5, 0)};
  EXPECT_FALSE(sweptEdgeEdge(sweeping, shifted(sweeping, Vec3(2, 0, 0)), past, past));
}

TEST(SweptEdgeEdge, FindsConstructedCrossingsOfRandomMotions) {
  std::mt19937 random(10);
  std::uniform_real_distribution<Real> coordinate(-1, 1);
  std::uniform_real_distribution<Real> unit(0.05, 0.95);
  auto point = [&]() { return Vec3(coordinate(random), coordinate(random), coordinate(random)); };
  for (int trial = 0; trial < 2000; ++trial) {
    const Edge firstStart = {point(), point()}, firstEnd = {point(), point()};
    const Real crossing = unit(random), s = unit(random), u = unit(random);
    auto lerp = [](const Vec3& a, const Vec3& b, Real t) { return Vec3(a + t * (b - a)); };
    const Vec3 meeting = lerp(lerp(firstStart[0], firstEnd[0], crossing),
                              lerp(firstStart[1], firstEnd[1], crossing), s);
    // The second edge: q0 random, q1 chosen so that q0 + u (q1 − q0) = meeting at t*.
    const Edge secondStart = {point(), point()};
    const Vec3 q0End = point();
    const Vec3 q0AtCrossing = lerp(secondStart[0], q0End, crossing);
    const Vec3 q1AtCrossing = q0AtCrossing + (meeting - q0AtCrossing) / u;
    const Vec3 q1End = secondStart[1] + (q1AtCrossing - secondStart[1]) / crossing;
    const Edge secondEnd = {q0End, q1End};
    const auto impact = sweptEdgeEdge(firstStart, firstEnd, secondStart, secondEnd);
    ASSERT_TRUE(impact) << "trial " << trial;
    EXPECT_LE(impact->time, crossing + 1e-9) << "trial " << trial;
    const Real t = impact->time;
    const SegmentClosestPoints closest = closestPointsOnSegments(
        lerp(firstStart[0], firstEnd[0], t), lerp(firstStart[1], firstEnd[1], t),
        lerp(secondStart[0], secondEnd[0], t), lerp(secondStart[1], secondEnd[1], t));
    EXPECT_LE(closest.distance, 1e-6) << "trial " << trial;
  }
}

}  // namespace
}  // namespace weft
