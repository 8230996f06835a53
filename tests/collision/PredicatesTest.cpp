// Exact orientation predicates against integer arithmetic, on inputs where plain doubles fail.
#include "Predicates.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

namespace weft {
namespace {

using detail::orient2d;
using detail::orient3d;

int exactOrient3d(const std::array<std::int64_t, 3>& a, const std::array<std::int64_t, 3>& b,
                  const std::array<std::int64_t, 3>& c, const std::array<std::int64_t, 3>& d) {
  __int128 m[3][3];
  for (int i = 0; i < 3; ++i) {
    m[0][i] = a[i] - d[i];
    m[1][i] = b[i] - d[i];
    m[2][i] = c[i] - d[i];
  }
  const __int128 det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                       m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                       m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  return (det > 0) - (det < 0);
}

Vec3 toVec(const std::array<std::int64_t, 3>& x, Real scale) {
  return Vec3(Real(x[0]) * scale, Real(x[1]) * scale, Real(x[2]) * scale);
}

TEST(Predicates, Orient3dSignConvention) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);  // normal (b − a) × (c − a) = +z
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.2, 0.2, -1)), 1);
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.2, 0.2, 1)), -1);
  EXPECT_EQ(orient3d(a, b, c, Vec3(5, -7, 0)), 0);
  EXPECT_EQ(orient2d(Vec2(0, 0), Vec2(1, 0), Vec2(0, 1)), 1);
  EXPECT_EQ(orient2d(Vec2(0, 0), Vec2(0, 1), Vec2(1, 0)), -1);
  EXPECT_EQ(orient2d(Vec2(0, 0), Vec2(1, 1), Vec2(3, 3)), 0);
}

TEST(Predicates, Orient3dIsExactOnNearlyCoplanarIntegerPoints) {
  // Points on a plane n · x = k with 2^26-sized coordinates, then nudged by ±1 or 0: the
  // determinants are tiny against the products (2^78), far below what doubles resolve, and
  // the scale by 2^-20 (exact) moves them into metres.
  std::mt19937_64 random(42);
  std::uniform_int_distribution<std::int64_t> coordinate(-(1 << 26), 1 << 26);
  std::uniform_int_distribution<int> nudge(-1, 1);
  const Real scale = std::ldexp(1.0, -20);
  int zeros = 0, disagreementsWithNaiveDouble = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    // Plane x + 3 y − 2 z = const through integer points: z is set so that x + 3y is even.
    auto onPlane = [&]() {
      std::int64_t x = coordinate(random), y = coordinate(random);
      if ((x + 3 * y) % 2 != 0) ++x;
      return std::array<std::int64_t, 3>{x, y, (x + 3 * y) / 2};
    };
    const auto a = onPlane(), b = onPlane(), c = onPlane();
    auto d = onPlane();
    d[2] += nudge(random);
    const int expected = exactOrient3d(a, b, c, d);
    EXPECT_EQ(orient3d(toVec(a, scale), toVec(b, scale), toVec(c, scale), toVec(d, scale)),
              expected)
        << "trial " << trial;
    zeros += expected == 0;
    const Vec3 ad = toVec(a, scale) - toVec(d, scale), bd = toVec(b, scale) - toVec(d, scale),
               cd = toVec(c, scale) - toVec(d, scale);
    const Real naive = ad.dot(bd.cross(cd));
    disagreementsWithNaiveDouble += ((naive > 0) - (naive < 0)) != expected;
  }
  EXPECT_GT(zeros, 500);
  EXPECT_GT(disagreementsWithNaiveDouble, 100) << "the inputs should defeat plain doubles";
}

TEST(Predicates, Orient2dIsExactOnNearlyCollinearPoints) {
  std::mt19937_64 random(7);
  std::uniform_int_distribution<std::int64_t> coordinate(-(1 << 30), 1 << 30);
  std::uniform_int_distribution<int> nudge(-1, 1);
  for (int trial = 0; trial < 3000; ++trial) {
    // Points on the line y = 3x + 1 (exact integers), the last nudged.
    const std::int64_t xa = coordinate(random), xb = coordinate(random), xc = coordinate(random);
    const std::int64_t ya = 3 * xa + 1, yb = 3 * xb + 1, yc = 3 * xc + 1 + nudge(random);
    const __int128 det = __int128(xa - xc) * (yb - yc) - __int128(ya - yc) * (xb - xc);
    const int expected = (det > 0) - (det < 0);
    EXPECT_EQ(orient2d(Vec2(Real(xa), Real(ya)), Vec2(Real(xb), Real(yb)), Vec2(Real(xc), Real(yc))),
              expected)
        << "trial " << trial;
  }
}

TEST(Predicates, Orient3dSeesOneUlpOffThePlane) {
  // A point one ulp above z = 0.1 against a triangle exactly at z = 0.1: a non-zero answer,
  // with the right sign, although every product rounds.
  const Vec3 a(0.1, 0.7, 0.1), b(0.9, 0.3, 0.1), c(0.3, 0.9, 0.1);
  const Real above = std::nextafter(0.1, 1.0);
  const Real below = std::nextafter(0.1, 0.0);
  const int sideOfNormal = orient3d(a, b, c, Vec3(0.5, 0.5, 1.0));
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.4, 0.6, above)), sideOfNormal);
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.4, 0.6, below)), -sideOfNormal);
  EXPECT_EQ(orient3d(a, b, c, Vec3(0.4, 0.6, 0.1)), 0);
}

}  // namespace
}  // namespace weft
