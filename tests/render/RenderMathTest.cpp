#include "PrimitiveMesh.h"
#include "RenderMath.h"
#include "RenderTestSupport.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace weft::test {
namespace {

TEST(RenderMath, FlatGridNormalsPointToTheFront) {
  const GridCloth square = makeFlatSquare(1.0, 5);
  std::vector<Vec3> normals;
  computeAreaWeightedNormals(square.positions, square.indices, normals);
  ASSERT_EQ(normals.size(), square.positions.size());
  for (const Vec3& n : normals) EXPECT_NEAR((n - Vec3::UnitZ()).norm(), 0.0, 1e-12);
}

TEST(RenderMath, NormalsAreWeightedByArea) {
  // Two triangles sharing vertex 0: a big one facing +z (area 2) and a small one facing +x (area 0.5).
  const std::vector<Vec3> positions = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  const std::vector<Index> indices = {0, 1, 2, 0, 3, 4};
  std::vector<Vec3> normals;
  computeAreaWeightedNormals(positions, indices, normals);
  const Vec3 expected = Vec3(0.5, 0, 2).normalized();
  EXPECT_NEAR((normals[0] - expected).norm(), 0.0, 1e-12);
  EXPECT_NEAR((normals[1] - Vec3::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((normals[3] - Vec3::UnitX()).norm(), 0.0, 1e-12);
}

TEST(RenderMath, DegenerateTrianglesGiveZeroNormalsNotNaN) {
  const std::vector<Vec3> positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  const std::vector<Index> indices = {0, 1, 2};
  std::vector<Vec3> normals;
  computeAreaWeightedNormals(positions, indices, normals);
  for (const Vec3& n : normals) EXPECT_EQ(n, Vec3::Zero());
}

TEST(RenderMath, LookAtPutsTheTargetOnTheNegativeZAxis) {
  const Vec3 eye(1, 2, 3), target(-1, 0.5, -2);
  const Mat4 view = lookAtMatrix(eye, target, Vec3::UnitY());
  const Eigen::Vector4d e = view * Vec3(eye).homogeneous();
  const Eigen::Vector4d t = view * Vec3(target).homogeneous();
  EXPECT_NEAR(e.head<3>().norm(), 0.0, 1e-12);
  EXPECT_NEAR(t.x(), 0.0, 1e-12);
  EXPECT_NEAR(t.y(), 0.0, 1e-12);
  EXPECT_NEAR(t.z(), -(target - eye).norm(), 1e-12);
  // Up stays up: a point above the target has positive view-space y.
  EXPECT_GT((view * Vec3(target + Vec3::UnitY()).homogeneous()).y(), 0.0);
  // Up parallel to the view direction still gives a rotation.
  const Mat4 straightDown = lookAtMatrix(Vec3(0, 5, 0), Vec3::Zero(), Vec3::UnitY());
  EXPECT_TRUE(straightDown.allFinite());
  EXPECT_NEAR((straightDown.block<3, 3>(0, 0).determinant()), 1.0, 1e-12);
}

TEST(RenderMath, PerspectiveMapsTheFieldOfViewEdgeToTheImageEdge) {
  const double fov = 60.0, aspect = 2.0, nearDistance = 0.1, farDistance = 50.0;
  const Mat4 projection = perspectiveMatrix(fov, aspect, nearDistance, farDistance);
  const double depth = 4.0;
  const double halfHeight = depth * std::tan(fov * std::numbers::pi / 360.0);
  const Eigen::Vector4d top = projection * Eigen::Vector4d(0, halfHeight, -depth, 1);
  const Eigen::Vector4d right = projection * Eigen::Vector4d(halfHeight * aspect, 0, -depth, 1);
  EXPECT_NEAR(top.y() / top.w(), 1.0, 1e-12);
  EXPECT_NEAR(right.x() / right.w(), 1.0, 1e-12);
  const Eigen::Vector4d nearPoint = projection * Eigen::Vector4d(0, 0, -nearDistance, 1);
  const Eigen::Vector4d farPoint = projection * Eigen::Vector4d(0, 0, -farDistance, 1);
  EXPECT_NEAR(nearPoint.z() / nearPoint.w(), -1.0, 1e-12);
  EXPECT_NEAR(farPoint.z() / farPoint.w(), 1.0, 1e-9);
}

// Every primitive mesh winds counter-clockwise seen from outside: the geometric normal of each
// triangle agrees with its vertex normals.
TEST(RenderMath, PrimitiveMeshesWindOutwards) {
  const std::pair<const char*, PrimitiveMesh> meshes[] = {
      {"sphere", makeSphereMesh()}, {"cylinder", makeCylinderMesh()}, {"quad", makeQuadMesh()}, {"cube", makeCubeMesh()}};
  for (const auto& [name, mesh] : meshes) {
    ASSERT_EQ(mesh.indices.size() % 3, 0u) << name;
    ASSERT_FALSE(mesh.indices.empty()) << name;
    const auto vertex = [&](std::uint32_t i) {
      const float* v = &mesh.vertices[i * PrimitiveMesh::kFloatsPerVertex];
      return std::pair{Vec3(v[0], v[1], v[2]), Vec3(v[3], v[4], v[5])};
    };
    for (std::size_t t = 0; t < mesh.indices.size(); t += 3) {
      const auto [p0, n0] = vertex(mesh.indices[t]);
      const auto [p1, n1] = vertex(mesh.indices[t + 1]);
      const auto [p2, n2] = vertex(mesh.indices[t + 2]);
      const Vec3 face = (p1 - p0).cross(p2 - p0);
      ASSERT_GT(face.norm(), 1e-6) << name << " triangle " << t / 3 << " is degenerate";
      EXPECT_GT(face.dot(n0 + n1 + n2), 0.0) << name << " triangle " << t / 3 << " winds inwards";
    }
  }
}

}  // namespace
}  // namespace weft::test
