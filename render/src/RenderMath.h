// Pure geometry for the renderer, free of GL so tests can check it alone: camera matrices in the
// OpenGL convention (right-handed view space looking down −z, clip depth −1..1) and area-weighted
// vertex normals.
#pragma once

#include <weft/Math.h>
#include <weft/render/RenderSettings.h>

#include <Eigen/Geometry>

#include <span>
#include <vector>

namespace weft {

using Mat4 = Eigen::Matrix<Real, 4, 4>;

/// World → view transform of a camera at eye looking at target (gluLookAt). Falls back to another
/// up vector when up is parallel to the viewing direction.
Mat4 lookAtMatrix(const Vec3& eye, const Vec3& target, const Vec3& up);

/// View → clip transform (gluPerspective); verticalFovDegrees is the full vertical angle.
Mat4 perspectiveMatrix(Real verticalFovDegrees, Real aspect, Real nearDistance, Real farDistance);

/// Sum over the triangles around each vertex of (x1 − x0) × (x2 − x0) (twice the area times the
/// unit normal), normalised; zero for vertices of degenerate triangles only. The caller has checked
/// the indices. normals is resized to positions.size() (allocation reused).
void computeAreaWeightedNormals(std::span<const Vec3> positions, std::span<const Index> indices,
                                std::vector<Vec3>& normals);

/// A unit vector perpendicular to n (n need not be unit; returns x when n is zero).
Vec3 anyPerpendicular(const Vec3& n);

}  // namespace weft
