#include "RigidFit.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

// Points whose RMS distance from their centroid is below this (m) coincide: no direction is
// determined (pins are placed to round-off at metres, far below a nanometre).
constexpr Real kCoincidentSpread = 1e-9;
// Collinear when the second singular value of the cross-covariance is below this fraction of the
// first: the singular values go as the squared spreads, so the points stray from their line by
// less than a thousandth of its length, and the turn about the line would be decided by
// round-off or an animation's jitter rather than by the pins.
constexpr Real kCollinearRatio = 1e-6;
// A fitted rotation this close to the identity (Frobenius norm of R − I) is the identity: the
// SVD of an unturned set returns it only to round-off.
constexpr Real kIdentityTolerance = 1e-12;
// sin of the angle below which a direction counts as along `up` (no plane through both).
constexpr Real kParallelSine = 1e-6;

// Orthonormal frame whose first axis is `direction` (unit) and whose second lies in the plane of
// `direction` and `up`; false when `up` is (nearly) along `direction` or zero.
bool frameAlong(const Vec3& direction, const Vec3& up, Mat3& frame) {
  const Vec3 across = up - up.dot(direction) * direction;
  const Real upLength = up.norm();
  if (!(upLength > 0) || across.norm() <= kParallelSine * upLength) return false;
  frame.col(0) = direction;
  frame.col(1) = across.normalized();
  frame.col(2) = direction.cross(frame.col(1));
  return true;
}

}  // namespace

Real RigidFit::angle() const {
  // trace R = 1 + 2 cos θ; clamped, since round-off may leave |cos θ| a hair over 1.
  return std::acos(std::clamp((rotation.trace() - 1) / 2, Real(-1), Real(1)));
}

RigidFit fitRigidMotion(std::span<const Vec3> from, std::span<const Vec3> to, const Vec3& up) {
  RigidFit fit;
  const std::size_t count = from.size();
  if (count == 0 || to.size() != count) return fit;
  for (std::size_t k = 0; k < count; ++k) {
    fit.fromCentroid += from[k];
    fit.toCentroid += to[k];
    fit.meanDisplacement += to[k] - from[k];
  }
  fit.fromCentroid /= Real(count);
  fit.toCentroid /= Real(count);
  fit.meanDisplacement /= Real(count);
  if (count == 1) return fit;

  Mat3 covariance = Mat3::Zero();  // Σ (from − c_from)(to − c_to)ᵀ
  Real spread2 = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const Vec3 a = from[k] - fit.fromCentroid;
    covariance += a * (to[k] - fit.toCentroid).transpose();
    spread2 += a.squaredNorm();
  }
  if (!(std::sqrt(spread2 / Real(count)) > kCoincidentSpread)) return fit;

  const Eigen::JacobiSVD<Mat3> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 sigma = svd.singularValues();  // decreasing
  const Mat3& u = svd.matrixU();
  const Mat3& v = svd.matrixV();
  Mat3 rotation;
  if (sigma(1) > kCollinearRatio * sigma(0)) {
    // R = V diag(1, 1, d) Uᵀ, d = sign det(V Uᵀ): the closest proper rotation (no reflection).
    Mat3 correction = Mat3::Identity();
    correction(2, 2) = (v * u.transpose()).determinant() < 0 ? -1 : 1;
    rotation = v * correction * u.transpose();
    fit.kind = RigidFitKind::Full;
  } else {
    // Collinear: covariance ≈ σ₀ u₀ v₀ᵀ, so u₀ (old line) maps onto v₀ (new line) with this sign.
    const Vec3 oldLine = u.col(0), newLine = v.col(0);
    Mat3 oldFrame, newFrame;
    if (frameAlong(oldLine, up, oldFrame) && frameAlong(newLine, up, newFrame)) {
      rotation = newFrame * oldFrame.transpose();
    } else {
      rotation = Eigen::Quaternion<Real>::FromTwoVectors(oldLine, newLine).toRotationMatrix();
    }
    fit.kind = RigidFitKind::Line;
  }
  if ((rotation - Mat3::Identity()).norm() <= kIdentityTolerance) {
    fit.kind = RigidFitKind::Translation;
    return fit;
  }
  fit.rotation = rotation;
  return fit;
}

}  // namespace weft
