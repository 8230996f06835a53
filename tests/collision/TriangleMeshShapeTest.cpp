// Triangle-mesh collider: a closed cube mesh must agree with the analytic Box everywhere (sign
// from pseudo-normals at faces, edges and corners); validation; kinematic pose.
#include <weft/collision/Box.h>
#include <weft/collision/TriangleMeshShape.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

namespace weft {
namespace {

using ::testing::HasSubstr;

// A cube [−h, h]³ with outward (counter-clockwise) winding, 12 triangles.
struct CubeMesh {
  std::vector<Vec3> vertices;
  std::vector<Index> indices;
};

CubeMesh makeCube(const Vec3& h) {
  CubeMesh cube;
  for (int i = 0; i < 8; ++i) {
    cube.vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                               (i & 4) ? h.z() : -h.z());
  }
  // Each face as a quad (counter-clockwise from outside), split in two.
  const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5},   // −x, +x
                           {0, 1, 5, 4}, {2, 6, 7, 3},   // −y, +y
                           {0, 2, 3, 1}, {4, 5, 7, 6}};  // −z, +z
  for (const auto& f : faces) {
    cube.indices.insert(cube.indices.end(), {Index(f[0]), Index(f[1]), Index(f[2]),
                                             Index(f[0]), Index(f[2]), Index(f[3])});
  }
  return cube;
}

TEST(TriangleMeshShape, ClosedCubeMatchesTheAnalyticBox) {
  const Vec3 half(0.5, 0.3, 0.2);
  const CubeMesh cube = makeCube(half);
  RigidMotion motion;
  motion.pose.position = Vec3(1, 2, 3);
  motion.pose.rotation = Quat(Eigen::AngleAxis<Real>(0.7, Vec3(1, 2, 3).normalized()));
  Result<TriangleMeshShape> mesh = TriangleMeshShape::create(cube.vertices, cube.indices, motion);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  Result<Box> box = Box::create(half, motion);
  ASSERT_TRUE(box.ok());

  std::mt19937 random(4);
  std::uniform_real_distribution<Real> coordinate(-1, 1);
  int inside = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 point = motion.pose.toWorld(Vec3(coordinate(random), coordinate(random),
                                                coordinate(random)));
    const ShapeContact fromMesh = mesh->queryPoint(point);
    const ShapeContact fromBox = box->queryPoint(point);
    ASSERT_NEAR(fromMesh.distance, fromBox.distance, 1e-12) << "trial " << trial;
    EXPECT_LT((fromMesh.point - fromBox.point).norm(), 1e-12) << "trial " << trial;
    EXPECT_LT((fromMesh.normal - fromBox.normal).norm(), 1e-9) << "trial " << trial;
    inside += fromBox.distance < 0;
  }
  EXPECT_GT(inside, 20);
  // Right at an edge and at a corner region outside: the sign comes from the pseudo-normals.
  const Vec3 nearCorner = motion.pose.toWorld(half + Vec3(1e-3, 2e-3, 3e-3));
  EXPECT_GT(mesh->queryPoint(nearCorner).distance, 0);
  const Vec3 justInsideCorner = motion.pose.toWorld(half - Vec3(1e-3, 2e-3, 3e-3));
  EXPECT_LT(mesh->queryPoint(justInsideCorner).distance, 0);
}

TEST(TriangleMeshShape, SurfaceVelocityOfAKinematicMesh) {
  const CubeMesh cube = makeCube(Vec3::Ones());
  RigidMotion motion;
  motion.angularVelocity = Vec3(0, 0, 1);  // spinning about z at 1 rad/s
  Result<TriangleMeshShape> mesh = TriangleMeshShape::create(cube.vertices, cube.indices, motion);
  ASSERT_TRUE(mesh.ok());
  const ShapeContact contact = mesh->queryPoint(Vec3(3, 0, 0));
  EXPECT_NEAR(contact.distance, 2, 1e-14);
  EXPECT_LT((contact.velocity - Vec3(0, 1, 0)).norm(), 1e-14);  // ω × (1, 0, 0)
  // worldVertices follows the pose.
  motion.pose.position = Vec3(0, 0, 5);
  ASSERT_TRUE(mesh->setMotion(motion).ok());
  std::vector<Vec3> world(cube.vertices.size());
  mesh->worldVertices(world);
  EXPECT_EQ(world[0], cube.vertices[0] + Vec3(0, 0, 5));
  EXPECT_TRUE(mesh->bounds().contains(world[7]));
}

TEST(TriangleMeshShape, ValidationErrors) {
  const CubeMesh cube = makeCube(Vec3::Ones());
  std::vector<Index> indices = cube.indices;
  Result<TriangleMeshShape> mesh = TriangleMeshShape::create(cube.vertices, std::vector<Index>{});
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("no triangles"));

  indices.pop_back();
  mesh = TriangleMeshShape::create(cube.vertices, indices);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("35 indices is not a multiple of three"));

  indices = cube.indices;
  indices[4] = 8;
  mesh = TriangleMeshShape::create(cube.vertices, indices);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("triangle 1"));
  EXPECT_THAT(mesh.error().message, HasSubstr("index 8 is out of range"));

  indices = cube.indices;
  indices[5] = indices[3];
  mesh = TriangleMeshShape::create(cube.vertices, indices);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("repeated vertex index"));

  std::vector<Vec3> vertices = cube.vertices;
  vertices[2] = 0.5 * (vertices[0] + vertices[6]);  // collinear with 0 and 6 in face −x
  mesh = TriangleMeshShape::create(vertices, cube.indices);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("zero area"));

  vertices = cube.vertices;
  vertices[3].z() = std::numeric_limits<Real>::infinity();
  mesh = TriangleMeshShape::create(vertices, cube.indices);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("vertex 3"));
}

}  // namespace
}  // namespace weft
