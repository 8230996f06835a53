#include "RenderMath.h"

#include <cmath>
#include <numbers>

namespace weft {

Vec3 anyPerpendicular(const Vec3& n) {
  if (n.squaredNorm() == 0) return Vec3::UnitX();
  // Cross with the world axis least aligned with n: never parallel, so never degenerate.
  Vec3 axis = Vec3::UnitX();
  if (std::abs(n.y()) < std::abs(n.x()) && std::abs(n.y()) <= std::abs(n.z())) axis = Vec3::UnitY();
  else if (std::abs(n.z()) < std::abs(n.x())) axis = Vec3::UnitZ();
  return n.cross(axis).normalized();
}

Mat4 lookAtMatrix(const Vec3& eye, const Vec3& target, const Vec3& up) {
  Vec3 forward = target - eye;
  if (forward.squaredNorm() == 0) forward = -Vec3::UnitZ();
  forward.normalize();
  Vec3 right = forward.cross(up);
  // up parallel to the view direction (or zero): any perpendicular will do.
  if (up.squaredNorm() == 0 || right.squaredNorm() <= 1e-12 * up.squaredNorm()) {
    right = anyPerpendicular(forward);
  }
  right.normalize();
  const Vec3 trueUp = right.cross(forward);
  Mat4 view = Mat4::Identity();
  view.block<1, 3>(0, 0) = right.transpose();
  view.block<1, 3>(1, 0) = trueUp.transpose();
  view.block<1, 3>(2, 0) = -forward.transpose();
  view(0, 3) = -right.dot(eye);
  view(1, 3) = -trueUp.dot(eye);
  view(2, 3) = forward.dot(eye);
  return view;
}

Mat4 perspectiveMatrix(Real verticalFovDegrees, Real aspect, Real nearDistance, Real farDistance) {
  const Real f = 1.0 / std::tan(verticalFovDegrees * std::numbers::pi / 360.0);
  Mat4 projection = Mat4::Zero();
  projection(0, 0) = f / aspect;
  projection(1, 1) = f;
  projection(2, 2) = (farDistance + nearDistance) / (nearDistance - farDistance);
  projection(2, 3) = 2.0 * farDistance * nearDistance / (nearDistance - farDistance);
  projection(3, 2) = -1.0;
  return projection;
}

void computeAreaWeightedNormals(std::span<const Vec3> positions, std::span<const Index> indices,
                                std::vector<Vec3>& normals) {
  normals.assign(positions.size(), Vec3::Zero());
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Index i0 = indices[t], i1 = indices[t + 1], i2 = indices[t + 2];
    // Unnormalised cross product: its length is twice the area, which is the weight we want.
    const Vec3 weighted = (positions[i1] - positions[i0]).cross(positions[i2] - positions[i0]);
    normals[i0] += weighted;
    normals[i1] += weighted;
    normals[i2] += weighted;
  }
  for (Vec3& n : normals) {
    const Real length = n.norm();
    n = length > 0 ? Vec3(n / length) : Vec3::Zero();
  }
}

}  // namespace weft
