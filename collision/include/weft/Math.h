// Scalar and vector types shared by every module above threading.
//
// Weft computes in double precision: the implicit solve, the accuracy references of the
// error-versus-time sweep and the finite-difference tests of the force kernels all want it, and at curtain sizes the
// state is small enough that bandwidth, not precision, is not what limits a step. Renderers
// convert to float at the boundary.
//
// (This header lives in the collision module because collision is the lowest module that does
// geometry; engine and render see it through their dependency on weft::collision.)
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

#include <cstdint>
#include <limits>
#include <vector>

namespace weft {

using Real = double;
using Vec2 = Eigen::Matrix<Real, 2, 1>;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat2 = Eigen::Matrix<Real, 2, 2>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;

/// One Vec3 per vertex; the layout of positions, velocities, forces and solver vectors.
using Vec3Array = std::vector<Vec3>;

/// Index of a vertex (or triangle) inside one cloth.
using Index = std::uint32_t;

inline constexpr Index kInvalidIndex = std::numeric_limits<Index>::max();

/// True when every component is finite (no NaN, no infinity).
inline bool isFinite(const Vec3& v) { return v.allFinite(); }

/// The matrix [v]ₓ with [v]ₓ a = v × a.
inline Mat3 crossMatrix(const Vec3& v) {
  Mat3 m;
  m << 0, -v.z(), v.y(),  //
      v.z(), 0, -v.x(),   //
      -v.y(), v.x(), 0;
  return m;
}

}  // namespace weft
