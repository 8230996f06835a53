// Triangle–triangle and segment–triangle tests on crafted cases (crossing, touching, separated,
// coplanar) and against a floating-point reference on random pairs far from degeneracy.
#include <weft/collision/TriangleIntersection.h>

#include <gtest/gtest.h>

#include <optional>
#include <random>

namespace weft {
namespace {

using Triangle = std::array<Vec3, 3>;

bool intersect(const Triangle& a, const Triangle& b) {
  const bool forward = trianglesIntersect(a[0], a[1], a[2], b[0], b[1], b[2]);
  // The answer must not depend on the order of the triangles or of their corners.
  EXPECT_EQ(forward, trianglesIntersect(b[0], b[1], b[2], a[0], a[1], a[2]));
  EXPECT_EQ(forward, trianglesIntersect(a[1], a[2], a[0], b[2], b[1], b[0]));
  return forward;
}

const Triangle kFloor = {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(0, 4, 0)};

TEST(TrianglesIntersect, CrossingPairs) {
  // A vertical triangle piercing the floor's interior.
  EXPECT_TRUE(intersect(kFloor, {Vec3(1, 1, -1), Vec3(1, 1, 1), Vec3(2, 1, 1)}));
  // An edge of each passes through the other (the "chain link" configuration).
  EXPECT_TRUE(intersect(kFloor, {Vec3(1, 1, -1), Vec3(1, 1, 1), Vec3(-3, 1, 1)}));
  // Crossing along a segment with no vertex of either triangle inside the other.
  EXPECT_TRUE(intersect({Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 2, 0)},
                        {Vec3(1, 0.5, -1), Vec3(1, 0.5, 1), Vec3(1, 5, 0)}));
}

TEST(TrianglesIntersect, TouchingPairsCount) {
  // A vertex exactly on the floor's interior.
  EXPECT_TRUE(intersect(kFloor, {Vec3(1, 1, 0), Vec3(1, 1, 1), Vec3(2, 1, 1)}));
  // A vertex exactly on the floor's edge.
  EXPECT_TRUE(intersect(kFloor, {Vec3(2, 0, 0), Vec3(2, -1, 1), Vec3(3, -1, 1)}));
  // Vertex on vertex.
  EXPECT_TRUE(intersect(kFloor, {Vec3(4, 0, 0), Vec3(5, 0, 1), Vec3(5, 1, 1)}));
  // Edge on edge: a vertical edge of a triangle in the plane x = 2 crosses the floor's edge
  // y = 0 at the single point (2, 0, 0); the rest of that triangle lies at y < 0.
  EXPECT_TRUE(intersect(kFloor, {Vec3(2, 0, -1), Vec3(2, 0, 1), Vec3(2, -1, 0)}));
  // The same, moved 1e-12 toward −y: separated.
  EXPECT_FALSE(intersect(kFloor, {Vec3(2, -1e-12, -1), Vec3(2, -1e-12, 1), Vec3(2, -1, 0)}));
}

TEST(TrianglesIntersect, SeparatedPairs) {
  // Parallel, 1e-9 above.
  EXPECT_FALSE(intersect(kFloor, {Vec3(0, 0, 1e-9), Vec3(4, 0, 1e-9), Vec3(0, 4, 1e-9)}));
  // A vertex 2^-60 above the floor's interior.
  const Real ulp = std::ldexp(1.0, -60);  // tiny but normal (no underflow in the products)
  EXPECT_FALSE(intersect(kFloor, {Vec3(1, 1, ulp), Vec3(1, 1, 1), Vec3(2, 1, 1)}));
  // Piercing the floor's plane just outside its hypotenuse.
  EXPECT_FALSE(intersect(kFloor, {Vec3(2.0, 2.0 + 1e-12, -1), Vec3(2.0, 2.0 + 1e-12, 1),
                                  Vec3(3, 3, 1)}));
  // Far apart.
  EXPECT_FALSE(intersect(kFloor, {Vec3(10, 10, 10), Vec3(11, 10, 10), Vec3(10, 11, 10)}));
}

TEST(TrianglesIntersect, CoplanarPairs) {
  // Overlapping in the plane.
  EXPECT_TRUE(intersect(kFloor, {Vec3(1, 1, 0), Vec3(5, 1, 0), Vec3(1, 5, 0)}));
  // One inside the other (no edges cross).
  EXPECT_TRUE(intersect(kFloor, {Vec3(0.5, 0.5, 0), Vec3(1, 0.5, 0), Vec3(0.5, 1, 0)}));
  // Sharing part of an edge.
  EXPECT_TRUE(intersect(kFloor, {Vec3(1, 0, 0), Vec3(3, 0, 0), Vec3(2, -1, 0)}));
  // Touching at one vertex.
  EXPECT_TRUE(intersect(kFloor, {Vec3(4, 0, 0), Vec3(5, 0, 0), Vec3(5, -1, 0)}));
  // Disjoint in the plane, 1e-12 apart across the hypotenuse x + y = 4.
  EXPECT_FALSE(intersect(kFloor, {Vec3(2 + 1e-12, 2 + 1e-12, 0), Vec3(5, 2, 0), Vec3(2, 5, 0)}));
  // Coplanar in a tilted plane (through points with exact coordinates).
  const Triangle tilted = {Vec3(0, 0, 0), Vec3(4, 0, 4), Vec3(0, 4, 0)};
  EXPECT_TRUE(intersect(tilted, {Vec3(1, 1, 1), Vec3(3, 1, 3), Vec3(1, 2, 1)}));
  EXPECT_FALSE(intersect(tilted, {Vec3(3, 3, 3), Vec3(5, 3, 5), Vec3(3, 5, 3)}));
}

TEST(SegmentIntersectsTriangle, EndsOnThePlaneAndCoplanarSegments) {
  const Vec3 a(0, 0, 0), b(4, 0, 0), c(0, 4, 0);
  EXPECT_TRUE(segmentIntersectsTriangle(Vec3(1, 1, 0), Vec3(1, 1, 5), a, b, c));
  EXPECT_FALSE(segmentIntersectsTriangle(Vec3(5, 5, 0), Vec3(5, 5, 5), a, b, c));
  EXPECT_TRUE(segmentIntersectsTriangle(Vec3(-1, 1, 0), Vec3(5, 1, 0), a, b, c));  // coplanar
  EXPECT_FALSE(segmentIntersectsTriangle(Vec3(-1, 5, 0), Vec3(5, 5, 0), a, b, c));
  EXPECT_FALSE(segmentIntersectsTriangle(Vec3(1, 1, 1), Vec3(1, 1, 5), a, b, c));
}

// Floating-point reference for generic pairs: each edge's crossing point with the other plane,
// tested with barycentric coordinates; "unsure" when anything is within `margin` of a boundary.
std::optional<bool> referenceIntersect(const Triangle& a, const Triangle& b, Real margin) {
  bool any = false;
  for (int pass = 0; pass < 2; ++pass) {
    const Triangle& edges = pass == 0 ? a : b;
    const Triangle& face = pass == 0 ? b : a;
    const Vec3 normal = (face[1] - face[0]).cross(face[2] - face[0]).normalized();
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = edges[k];
      const Vec3& q = edges[(k + 1) % 3];
      const Real dp = (p - face[0]).dot(normal), dq = (q - face[0]).dot(normal);
      if (std::abs(dp) < margin || std::abs(dq) < margin) return std::nullopt;
      if ((dp > 0) == (dq > 0)) continue;
      const Vec3 x = p + (dp / (dp - dq)) * (q - p);
      // Barycentric coordinates of x in the face.
      const Vec3 v0 = face[1] - face[0], v1 = face[2] - face[0], v2 = x - face[0];
      const Real d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
      const Real d20 = v2.dot(v0), d21 = v2.dot(v1);
      const Real denominator = d00 * d11 - d01 * d01;
      const Real v = (d11 * d20 - d01 * d21) / denominator;
      const Real w = (d00 * d21 - d01 * d20) / denominator;
      const Real u = 1 - v - w;
      if (std::min({std::abs(u), std::abs(v), std::abs(w)}) < margin) return std::nullopt;
      if (u > 0 && v > 0 && w > 0) any = true;
    }
  }
  return any;
}

TEST(TrianglesIntersect, AgreesWithFloatingPointReferenceOnGenericRandomPairs) {
  std::mt19937 random(3);
  std::uniform_real_distribution<Real> coordinate(-1, 1);
  auto point = [&]() { return Vec3(coordinate(random), coordinate(random), coordinate(random)); };
  int compared = 0, intersecting = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const Triangle a = {point(), point(), point()};
    const Triangle b = {point(), point(), point()};
    const std::optional<bool> expected = referenceIntersect(a, b, 1e-6);
    if (!expected) continue;
    ++compared;
    intersecting += *expected;
    EXPECT_EQ(intersect(a, b), *expected) << "trial " << trial;
  }
  EXPECT_GT(compared, 4500);
  EXPECT_GT(intersecting, 500);
}

}  // namespace
}  // namespace weft
