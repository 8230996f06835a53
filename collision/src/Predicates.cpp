// Exact orientation predicates: double filter, then exact expansion arithmetic. See Predicates.h.
#include "Predicates.h"

#include <cmath>
#include <cstddef>
#include <limits>

namespace weft::detail {
namespace {

constexpr Real kEpsilon = std::numeric_limits<Real>::epsilon() / 2;  // 2^-53, unit round-off
// Shewchuk 1997, the first-stage error bounds of orient2d and orient3d.
constexpr Real kOrient2dBound = (3.0 + 16.0 * kEpsilon) * kEpsilon;
constexpr Real kOrient3dBound = (7.0 + 56.0 * kEpsilon) * kEpsilon;

// A floating-point expansion: components non-overlapping, in increasing magnitude, zeros
// dropped. 192 components is the most orient3d needs (3 × 2 × 2 × 16); kept on the stack.
struct Expansion {
  static constexpr std::size_t kCapacity = 256;
  Real terms[kCapacity];
  std::size_t size = 0;

  void push(Real x) {
    if (x != 0) terms[size++] = x;
  }
  int sign() const { return size == 0 ? 0 : (terms[size - 1] > 0 ? 1 : -1); }
  // Copies only the components in use (the array is large and mostly garbage).
  void assign(const Expansion& other) {
    size = other.size;
    for (std::size_t i = 0; i < size; ++i) terms[i] = other.terms[i];
  }
};

// x + y = sum + error exactly (Knuth's two-sum).
void twoSum(Real x, Real y, Real& sum, Real& error) {
  sum = x + y;
  const Real yVirtual = sum - x;
  const Real xVirtual = sum - yVirtual;
  error = (x - xVirtual) + (y - yVirtual);
}

// x · y = product + error exactly (fma computes the rounding error of the product).
void twoProduct(Real x, Real y, Real& product, Real& error) {
  product = x * y;
  error = std::fma(x, y, -product);
}

// result = e + b (Shewchuk's grow-expansion with zero elimination). result may not alias e.
void grow(const Expansion& e, Real b, Expansion& result) {
  result.size = 0;
  Real q = b;
  for (std::size_t i = 0; i < e.size; ++i) {
    Real sum, error;
    twoSum(q, e.terms[i], sum, error);
    result.push(error);
    q = sum;
  }
  result.push(q);
}

// e += b, in place through a scratch expansion.
void add(Expansion& e, Real b) {
  Expansion grown;
  grow(e, b, grown);
  e.assign(grown);
}

// e += f.
void add(Expansion& e, const Expansion& f) {
  for (std::size_t i = 0; i < f.size; ++i) add(e, f.terms[i]);
}

// result = e · f, exactly.
void multiply(const Expansion& e, const Expansion& f, Expansion& result) {
  result.size = 0;
  for (std::size_t i = 0; i < e.size; ++i) {
    for (std::size_t j = 0; j < f.size; ++j) {
      Real product, error;
      twoProduct(e.terms[i], f.terms[j], product, error);
      add(result, error);
      add(result, product);
    }
  }
}

// x − y as an exact expansion.
Expansion difference(Real x, Real y) {
  Expansion result;
  Real sum, error;
  twoSum(x, -y, sum, error);
  result.push(error);
  result.push(sum);
  return result;
}

void negate(Expansion& e) {
  for (std::size_t i = 0; i < e.size; ++i) e.terms[i] = -e.terms[i];
}

// (x1 · y2 − x2 · y1) exactly, from expansions.
Expansion crossTerm(const Expansion& x1, const Expansion& y2, const Expansion& x2,
                    const Expansion& y1) {
  Expansion first, second;
  multiply(x1, y2, first);
  multiply(x2, y1, second);
  negate(second);
  add(first, second);
  return first;
}

int orient3dExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Expansion adx = difference(a.x(), d.x()), ady = difference(a.y(), d.y()),
                  adz = difference(a.z(), d.z());
  const Expansion bdx = difference(b.x(), d.x()), bdy = difference(b.y(), d.y()),
                  bdz = difference(b.z(), d.z());
  const Expansion cdx = difference(c.x(), d.x()), cdy = difference(c.y(), d.y()),
                  cdz = difference(c.z(), d.z());
  // (b − d) × (c − d), component by component.
  const Expansion crossX = crossTerm(bdy, cdz, bdz, cdy);
  const Expansion crossY = crossTerm(bdz, cdx, bdx, cdz);
  const Expansion crossZ = crossTerm(bdx, cdy, bdy, cdx);
  Expansion determinant, term;
  multiply(adx, crossX, determinant);
  multiply(ady, crossY, term);
  add(determinant, term);
  multiply(adz, crossZ, term);
  add(determinant, term);
  return determinant.sign();
}

int orient2dExact(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Expansion acx = difference(a.x(), c.x()), acy = difference(a.y(), c.y());
  const Expansion bcx = difference(b.x(), c.x()), bcy = difference(b.y(), c.y());
  return crossTerm(acx, bcy, acy, bcx).sign();
}

int signOf(Real x) { return (x > 0) - (x < 0); }

}  // namespace

int orient2d(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Real left = (a.x() - c.x()) * (b.y() - c.y());
  const Real right = (a.y() - c.y()) * (b.x() - c.x());
  const Real determinant = left - right;
  const Real permanent = std::abs(left) + std::abs(right);
  if (permanent == 0) return 0;
  const Real bound = kOrient2dBound * permanent;
  if (determinant > bound || -determinant > bound) return signOf(determinant);
  return orient2dExact(a, b, c);
}

int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Real adx = a.x() - d.x(), ady = a.y() - d.y(), adz = a.z() - d.z();
  const Real bdx = b.x() - d.x(), bdy = b.y() - d.y(), bdz = b.z() - d.z();
  const Real cdx = c.x() - d.x(), cdy = c.y() - d.y(), cdz = c.z() - d.z();
  const Real bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const Real cdxady = cdx * ady, adxcdy = adx * cdy;
  const Real adxbdy = adx * bdy, bdxady = bdx * ady;
  const Real determinant =
      adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
  const Real permanent = (std::abs(bdxcdy) + std::abs(cdxbdy)) * std::abs(adz) +
                         (std::abs(cdxady) + std::abs(adxcdy)) * std::abs(bdz) +
                         (std::abs(adxbdy) + std::abs(bdxady)) * std::abs(cdz);
  // Every product is exactly zero (e.g. four points in a plane z = const): so is the determinant.
  if (permanent == 0) return 0;
  const Real bound = kOrient3dBound * permanent;
  if (determinant > bound || -determinant > bound) return signOf(determinant);
  return orient3dExact(a, b, c, d);
}

}  // namespace weft::detail
