// Hooke spring condition; see SpringCondition.h.
#include <forces/SpringCondition.h>

namespace weft {
namespace {

/// A spring shorter than this fraction of its rest length has collapsed: its direction is noise.
constexpr Real kCollapsedRatio = 1e-8;
/// m; absolute floor for springs of zero rest length, far below any cloth feature. The Hessian
/// grows like 1/|L|, so this also keeps it finite.
constexpr Real kMinLength = 1e-12;

}  // namespace

Condition<2> springCondition(const Vec3& x0, const Vec3& x1, Real restLength, bool withHessian) {
  Condition<2> condition;
  condition.convex = true;  // |x0 − x1| is convex
  const Vec3 spring = x0 - x1;
  const Real length = spring.norm();
  condition.value = length - restLength;
  if (!(length > kCollapsedRatio * restLength + kMinLength)) {
    return condition;
  }
  const Vec3 direction = spring / length;
  condition.gradient << direction, -direction;
  if (withHessian) {
    // ∂²|L|/∂L² = (I − L̂L̂ᵀ)/|L|; x0 and x1 enter L with opposite signs.
    const Mat3 across = (Mat3::Identity() - direction * direction.transpose()) / length;
    condition.hessian << across, -across, -across, across;
  }
  return condition;
}

}  // namespace weft
