// Triangle-mesh collider: a closed cube mesh must agree with the analytic Box everywhere (sign
// from pseudo-normals at faces, edges and corners); an open mesh (a one-quad table top) is a
// two-sided shell; the bounded queries and the segment crossing; how far the surface bulges
// round each edge; validation; kinematic pose.
#include "collision/CollisionTestSupport.h"

#include <weft/collision/Box.h>
#include <weft/collision/TriangleMeshShape.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
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

// A horizontal square table top [−h, h] × [−h, h] at height y, two triangles facing up.
CubeMesh makeTableTop(Real h, Real y) {
  CubeMesh top;
  top.vertices = {Vec3(-h, y, h), Vec3(h, y, h), Vec3(h, y, -h), Vec3(-h, y, -h)};
  top.indices = {0, 1, 2, 0, 2, 3};
  return top;
}

TEST(TriangleMeshShape, ClosedAndOpenMeshesAreTold) {
  const CubeMesh cube = makeCube(Vec3::Ones());
  EXPECT_TRUE(TriangleMeshShape::create(cube.vertices, cube.indices).value().isClosed());
  const CubeMesh top = makeTableTop(0.5, 0);
  EXPECT_FALSE(TriangleMeshShape::create(top.vertices, top.indices).value().isClosed());
  // A cube without its top face: every edge of the rim has one triangle.
  std::vector<Index> openBox(cube.indices.begin(), cube.indices.end());
  openBox.erase(openBox.begin() + 18, openBox.begin() + 24);  // the +y face
  EXPECT_FALSE(TriangleMeshShape::create(cube.vertices, openBox).value().isClosed());
  const std::vector<Vec3> one = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, -1)};
  EXPECT_FALSE(TriangleMeshShape::create(one, std::vector<Index>{0, 1, 2}).value().isClosed());
}

TEST(TriangleMeshShape, AnOpenMeshIsATwoSidedShell) {
  RigidMotion motion;
  motion.pose.position = Vec3(0.2, 0.75, -0.1);
  const CubeMesh top = makeTableTop(0.5, 0);
  const TriangleMeshShape mesh = TriangleMeshShape::create(top.vertices, top.indices, motion).value();
  // Below the top, anywhere in its shadow: the unsigned distance, the normal pointing down.
  for (const Real below : {1e-4, 3e-3, 0.05, 0.4, 3.0}) {
    for (const Vec3& across : {Vec3(0, 0, 0), Vec3(0.3, 0, -0.2), Vec3(-0.49, 0, 0.49)}) {
      const Vec3 point = motion.pose.position + across - Vec3(0, below, 0);
      const ShapeContact contact = mesh.queryPoint(point);
      EXPECT_NEAR(contact.distance, below, 1e-12) << "below " << below;
      EXPECT_LT((contact.normal - Vec3(0, -1, 0)).norm(), 1e-12) << "below " << below;
      EXPECT_LT((contact.point + below * contact.normal - point).norm(), 1e-12);
      // The same above, the normal pointing up.
      const ShapeContact above = mesh.queryPoint(point + Vec3(0, 2 * below, 0));
      EXPECT_NEAR(above.distance, below, 1e-12);
      EXPECT_LT((above.normal - Vec3(0, 1, 0)).norm(), 1e-12);
    }
  }
  // Beside and below the edge: towards the point from the edge.
  const ShapeContact beside = mesh.queryPoint(motion.pose.position + Vec3(0.8, -0.4, 0));
  EXPECT_NEAR(beside.distance, 0.5, 1e-12);
  EXPECT_LT((beside.normal - Vec3(0.6, -0.8, 0)).norm(), 1e-12);
  // On the surface (exactly: the mesh at the identity pose): the face normal.
  const TriangleMeshShape still = TriangleMeshShape::create(top.vertices, top.indices).value();
  const ShapeContact on = still.queryPoint(Vec3(0.125, 0, 0.25));
  EXPECT_EQ(on.distance, 0);
  EXPECT_LT((on.normal - Vec3(0, 1, 0)).norm(), 1e-12);
}

TEST(TriangleMeshShape, TheBoundedQueryAgreesWithinItsRangeAndPrunesBeyond) {
  const CubeMesh cube = makeCube(Vec3(0.5, 0.3, 0.2));
  const TriangleMeshShape mesh = TriangleMeshShape::create(cube.vertices, cube.indices).value();
  std::mt19937 random(9);
  std::uniform_real_distribution<Real> coordinate(-1.5, 1.5);
  int within = 0, beyond = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 point(coordinate(random), coordinate(random), coordinate(random));
    const ShapeContact exact = mesh.queryPoint(point);
    const std::optional<ShapeContact> bounded = mesh.queryPointWithin(point, 0.4);
    if (std::abs(exact.distance) < 0.4) {
      ASSERT_TRUE(bounded.has_value()) << "trial " << trial;
      EXPECT_EQ(bounded->distance, exact.distance);
      EXPECT_EQ(bounded->normal, exact.normal);
      EXPECT_EQ(bounded->point, exact.point);
      ++within;
    } else {
      EXPECT_FALSE(bounded.has_value()) << "trial " << trial;
      ++beyond;
    }
  }
  EXPECT_GT(within, 100);
  EXPECT_GT(beyond, 100);
}

TEST(TriangleMeshShape, TheQueryBelowADistanceFindsEveryPointInsideOrNearerAndNoOther) {
  const CubeMesh cube = makeCube(Vec3(0.5, 0.4, 0.3));
  const TriangleMeshShape mesh = TriangleMeshShape::create(cube.vertices, cube.indices).value();
  std::mt19937 random(11);
  std::uniform_real_distribution<Real> coordinate(-0.8, 0.8);
  int deepInside = 0, near = 0, beyond = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Vec3 point(coordinate(random), coordinate(random), coordinate(random));
    const ShapeContact exact = mesh.queryPoint(point);
    const std::optional<ShapeContact> below = mesh.queryPointBelow(point, 0.1);
    if (exact.distance < 0.1) {
      ASSERT_TRUE(below.has_value()) << "trial " << trial;
      EXPECT_EQ(below->distance, exact.distance);
      EXPECT_EQ(below->normal, exact.normal);
      deepInside += exact.distance <= -0.1;  // beyond the pruned search: found through the box
      near += std::abs(exact.distance) < 0.1;
    } else {
      EXPECT_FALSE(below.has_value()) << "trial " << trial;
      ++beyond;
    }
  }
  EXPECT_GT(deepInside, 10);
  EXPECT_GT(near, 100);
  EXPECT_GT(beyond, 100);
}

TEST(TriangleMeshShape, TheMostBulgeIsTheLargestOfItsEdgesAndVertices) {
  // maxBulge(span) is what lets a face skip a mesh's tree: it must be at least every edge's bulge
  // and every vertex's rise at that span (bit for bit: the face tests compare against it), and
  // no more than the largest of them.
  const test::MeshArrays rod = test::makeCylinder(0.3, 0.3, 48);
  const CubeMesh cube = makeCube(Vec3(0.5, 0.5, 0.5));
  const CubeMesh top = makeTableTop(0.5, 0);
  const TriangleMeshShape shapes[] = {
      TriangleMeshShape::create(rod.positions, rod.indices).value(),
      TriangleMeshShape::create(cube.vertices, cube.indices).value(),
      TriangleMeshShape::create(top.vertices, top.indices).value()};
  for (const TriangleMeshShape& shape : shapes) {
    for (Real span : {1e-4, 0.01, 0.05, 0.3, 2.0}) {
      Real largest = 0;
      for (const MeshEdge& edge : shape.edges()) largest = std::max(largest, edge.bulge(span));
      for (Index v = 0; v < Index(shape.localVertices().size()); ++v) {
        largest = std::max(largest, shape.vertexSlope(v) * span / 2);
      }
      EXPECT_EQ(shape.maxBulge(span), largest) << shape.triangleCount() << " triangles, span " << span;
    }
  }
  // The open quad's border is a fin: it bulges without bound at any span.
  EXPECT_TRUE(std::isinf(shapes[2].maxBulge(1e-6)));
}

TEST(TriangleMeshShape, EdgesKnowHowFarTheSurfaceBulgesIntoAFaceOverThem) {
  // A cube: its twelve edges turn a right angle (slope tan 45° = 1), the diagonals of its faces
  // not at all; a corner's faces stand 54.7° off its normal (slope √2).
  const CubeMesh cube = makeCube(Vec3(0.5, 0.5, 0.5));
  const TriangleMeshShape box = TriangleMeshShape::create(cube.vertices, cube.indices).value();
  ASSERT_EQ(box.edges().size(), 18u);
  int sharp = 0, flat = 0;
  for (const MeshEdge& edge : box.edges()) {
    EXPECT_LT(edge.a, edge.b);
    if (std::abs(edge.ridgeSlope - 1) < 1e-12) {
      ++sharp;
      EXPECT_NEAR(edge.bulge(0.1), 0.05, 1e-12);  // a ridge: span / 2 · slope
    } else if (edge.ridgeSlope < 1e-12) {
      ++flat;
      EXPECT_EQ(edge.bulge(10), 0);
    }
  }
  EXPECT_EQ(sharp, 12);
  EXPECT_EQ(flat, 6);
  for (Index v = 0; v < 8; ++v) EXPECT_NEAR(box.vertexSlope(v), std::sqrt(2.0), 1e-12);
  for (Index t = 0; t < box.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const MeshEdge& edge = box.edges()[box.triangleEdges(t)[k]];
      const Index a = cube.indices[3 * t + k], b = cube.indices[3 * t + (k + 1) % 3];
      EXPECT_EQ(edge.a, std::min(a, b));
      EXPECT_EQ(edge.b, std::max(a, b));
    }
  }

  // A fine cylinder of radius R: each side edge turns 2π/n, over triangles 2πR/n wide, so its
  // curvature is about 1/(2R) (a circle's sag span²/(8R) = span² · curvature / 4); the rims
  // are right angles.
  const Real radius = 0.02;
  const Index n = 256;
  const test::MeshArrays rod = test::makeCylinder(radius, 0.5, n);
  const TriangleMeshShape fine = TriangleMeshShape::create(rod.positions, rod.indices).value();
  int sides = 0;
  for (const MeshEdge& edge : fine.edges()) {
    const bool side = edge.a < n && edge.b == edge.a + n;  // the vertical edges
    if (!side) continue;
    ++sides;
    EXPECT_NEAR(edge.ridgeSlope, std::tan(M_PI / Real(n)), 1e-9);
    EXPECT_NEAR(edge.curvature, 1 / (2 * radius), 0.001 / radius);
    // A 5 cm face across the rod: the ridge alone says 0.3 mm, the curvature 16 mm.
    EXPECT_LT(edge.ridgeSlope * 0.05 / 2, 0.0004);
    EXPECT_GT(edge.bulge(0.05), 0.015);
  }
  EXPECT_EQ(sides, int(n));

  // An open quad: its border is a fin of one triangle (infinite), its diagonal flat.
  const CubeMesh top = makeTableTop(0.5, 0);
  const TriangleMeshShape quad = TriangleMeshShape::create(top.vertices, top.indices).value();
  int borders = 0;
  for (const MeshEdge& edge : quad.edges()) {
    if (std::isinf(edge.ridgeSlope)) {
      ++borders;
      EXPECT_TRUE(std::isinf(edge.bulge(1e-6)));
    } else {
      EXPECT_EQ(edge.bulge(1), 0);
    }
  }
  EXPECT_EQ(borders, 4);
  for (Index v = 0; v < 4; ++v) EXPECT_EQ(quad.vertexSlope(v), 0);
}

TEST(TriangleMeshShape, TheFirstCrossingOfASegment) {
  const CubeMesh top = makeTableTop(0.5, 0);
  const TriangleMeshShape mesh = TriangleMeshShape::create(top.vertices, top.indices).value();
  const std::optional<Real> down = mesh.firstCrossing(Vec3(0.1, 0.3, 0), Vec3(0.1, -0.1, 0));
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(*down, 0.75, 1e-12);
  EXPECT_FALSE(mesh.firstCrossing(Vec3(0.1, 0.3, 0), Vec3(0.1, 0.01, 0)).has_value());
  EXPECT_FALSE(mesh.firstCrossing(Vec3(0.6, 0.3, 0), Vec3(0.6, -0.3, 0)).has_value());  // beside
  EXPECT_FALSE(mesh.firstCrossing(Vec3(0.1, 0.3, 0), Vec3(0.1, 0.3, 0)).has_value());
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
