// ClothModel construction: counts, masses, rest state, and every bad-mesh case with its message.
#include <weft/engine/ClothModel.h>

#include "forces/BaraffWitkin.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

namespace weft {
namespace {

using ::testing::HasSubstr;

ClothModel curtainGrid() {
  Result<ClothModel> model = ClothModel::grid(GridSettings{});
  EXPECT_TRUE(model.ok()) << model.error().message;
  return std::move(model).value();
}

// Two triangles sharing the edge (0, 1): a unit square split along its diagonal.
TriangleMesh unitSquare() {
  TriangleMesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  mesh.indices = {0, 2, 1, 0, 1, 3};
  return mesh;
}

std::string writeTemporaryFile(const std::string& name, const std::string& text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

TEST(ClothModelGrid, CurtainCountsMatchDesign) {
  const ClothModel model = curtainGrid();
  EXPECT_EQ(model.vertexCount(), 1271u);
  EXPECT_EQ(model.triangleCount(), 2400u);
  EXPECT_EQ(model.indices().size(), 7200u);
  // Edges: 40·31 horizontal + 30·41 vertical + 40·30 diagonals.
  EXPECT_EQ(model.edges().size(), 3670u);
  // Every edge but the 2·(40 + 30) on the border is interior and carries a hinge.
  EXPECT_EQ(model.hinges().size(), 3670u - 140u);
  EXPECT_EQ((model.gridSize()), (std::array<Index, 2>{41, 31}));
}

TEST(ClothModelGrid, SpringNetworkIsTheClassicOne) {
  const ClothModel model = curtainGrid();
  std::size_t structural = 0, shear = 0, flexion = 0;
  for (const Spring& spring : model.springs()) {
    const Real expected = (model.restPositions()[spring.vertices[0]] -
                           model.restPositions()[spring.vertices[1]]).norm();
    EXPECT_NEAR(spring.restLength, expected, 1e-12);
    switch (spring.kind) {
      case SpringKind::Structural: ++structural; EXPECT_NEAR(spring.restLength, 0.05, 1e-12); break;
      case SpringKind::Shear: ++shear; EXPECT_NEAR(spring.restLength, 0.05 * std::sqrt(2.0), 1e-12); break;
      case SpringKind::Flexion: ++flexion; EXPECT_NEAR(spring.restLength, 0.10, 1e-12); break;
    }
  }
  EXPECT_EQ(structural, 40u * 31u + 30u * 41u);
  EXPECT_EQ(shear, 2u * 40u * 30u);
  EXPECT_EQ(flexion, 39u * 31u + 29u * 41u);
}

TEST(ClothModelGrid, MassIsDensityTimesArea) {
  const ClothModel model = curtainGrid();
  EXPECT_NEAR(model.totalArea(), 2.0 * 1.5, 1e-12);
  EXPECT_NEAR(model.totalMass(0.15), 0.45, 1e-12);
  const std::vector<Real> masses = model.vertexMasses(0.15);
  Real sum = 0;
  for (Real mass : masses) {
    EXPECT_GT(mass, 0);
    sum += mass;
  }
  EXPECT_NEAR(sum, 0.45, 1e-12);
  // An interior vertex touches six triangles of 0.05²/2 m²: a third of each.
  const Index interior = 15 * 41 + 20;
  EXPECT_NEAR(masses[interior], 0.15 * 6 * (0.05 * 0.05 / 2) / 3, 1e-15);
}

TEST(ClothModelGrid, RestParameterisationMapsToTheAxes) {
  const ClothModel model = curtainGrid();
  const Vec3Array& x = model.restPositions();
  EXPECT_TRUE(x[0].isApprox(Vec3(-1, 0.5, 0)));
  EXPECT_TRUE(x[1270].isApprox(Vec3(1, 2, 0)));
  for (const TriangleRest& triangle : model.triangles()) {
    Vec3 warp = Vec3::Zero(), weft = Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      warp += triangle.warpWeights[k] * x[triangle.vertices[k]];
      weft += triangle.weftWeights[k] * x[triangle.vertices[k]];
    }
    EXPECT_NEAR((warp - Vec3(1, 0, 0)).norm(), 0, 1e-9);
    EXPECT_NEAR((weft - Vec3(0, 1, 0)).norm(), 0, 1e-9);
    EXPECT_NEAR(triangle.area, 0.05 * 0.05 / 2, 1e-15);
  }
  for (const Hinge& hinge : model.hinges()) {
    EXPECT_NEAR(hinge.restAngle, 0, 1e-12);
    EXPECT_GT(hinge.stiffnessScale, 0);
  }
}

TEST(ClothModelGrid, FrontFacesAlongWidthCrossHeight) {
  const ClothModel model = curtainGrid();
  const Vec3Array& x = model.restPositions();
  const std::vector<Index>& indices = model.indices();
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    const Vec3 normal = (x[indices[t + 1]] - x[indices[t]]).cross(x[indices[t + 2]] - x[indices[t]]);
    EXPECT_GT(normal.z(), 0) << "triangle " << t / 3;
  }
}

TEST(ClothModelGrid, HingesFollowTheDrawnConvention) {
  const ClothModel model = curtainGrid();
  const std::vector<Index>& indices = model.indices();
  for (const Hinge& hinge : model.hinges()) {
    // x0 -> x1 appears in triangle A's winding, x2 is A's third vertex, x3 is B's.
    const Index* a = &indices[3 * hinge.triangles[0]];
    bool found = false;
    for (int k = 0; k < 3; ++k) {
      found |= a[k] == hinge.vertices[0] && a[(k + 1) % 3] == hinge.vertices[1] &&
               a[(k + 2) % 3] == hinge.vertices[2];
    }
    EXPECT_TRUE(found);
    const Index* b = &indices[3 * hinge.triangles[1]];
    EXPECT_TRUE(b[0] == hinge.vertices[3] || b[1] == hinge.vertices[3] || b[2] == hinge.vertices[3]);
  }
}

TEST(ClothModelGrid, RejectsBadGrids) {
  GridSettings tooFew;
  tooFew.columns = 1;
  EXPECT_THAT(ClothModel::grid(tooFew).error().message, HasSubstr("at least 2 columns"));
  GridSettings flat;
  flat.width = 0;
  EXPECT_THAT(ClothModel::grid(flat).error().message, HasSubstr("greater than zero"));
  GridSettings nanSize;
  nanSize.height = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_FALSE(ClothModel::grid(nanSize).ok());
  GridSettings parallel;
  parallel.heightAxis = Vec3(1, 0, 0);
  EXPECT_THAT(ClothModel::grid(parallel).error().message, HasSubstr("perpendicular"));
}

TEST(ClothModelMesh, BuildsFromATriangleMesh) {
  Result<ClothModel> model = ClothModel::fromMesh(unitSquare());
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 4u);
  EXPECT_EQ(model->triangleCount(), 2u);
  EXPECT_EQ(model->edges().size(), 5u);
  ASSERT_EQ(model->hinges().size(), 1u);
  EXPECT_NEAR(model->totalArea(), 1.0, 1e-12);
  // Structural on the 5 edges, one shear spring across the diagonal, no straight 2-paths.
  std::size_t shear = 0;
  for (const Spring& spring : model->springs()) shear += spring.kind == SpringKind::Shear;
  EXPECT_EQ(model->springs().size(), 6u);
  EXPECT_EQ(shear, 1u);
}

TEST(ClothModelMesh, FoldedRestShapeKeepsItsAngle) {
  TriangleMesh mesh = unitSquare();
  mesh.positions[3] = Vec3(0, 0.5, 0.5);  // lift one wing out of the plane
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  const Hinge& hinge = model->hinges()[0];
  const Vec3Array& x = model->restPositions();
  EXPECT_NEAR(hinge.restAngle,
              dihedralAngle(x[hinge.vertices[0]], x[hinge.vertices[1]], x[hinge.vertices[2]],
                            x[hinge.vertices[3]]),
              1e-15);
  EXPECT_GT(std::abs(hinge.restAngle), 0.1);
  // Flattened per triangle: the rest area equals the 3D area.
  const Real area3d = 0.5 * (x[1] - x[0]).cross(x[3] - x[0]).norm();
  EXPECT_NEAR(model->triangles()[1].area, area3d, 1e-12);
}

TEST(ClothModelMesh, MaterialCoordinatesAreUsedWhenGiven) {
  TriangleMesh mesh = unitSquare();
  // Material twice as long along u as the geometry: the cloth starts compressed along the warp.
  mesh.materialCoordinates = {Vec2(0, 0), Vec2(2, 1), Vec2(2, 0), Vec2(0, 1)};
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_NEAR(model->totalArea(), 2.0, 1e-12);
  const TriangleRest& triangle = model->triangles()[0];
  Vec3 warp = Vec3::Zero();
  for (int k = 0; k < 3; ++k) warp += triangle.warpWeights[k] * mesh.positions[triangle.vertices[k]];
  EXPECT_NEAR(warp.norm(), 0.5, 1e-12);
}

struct BadMeshCase {
  const char* name;
  void (*spoil)(TriangleMesh&);
  const char* message;
};

class ClothModelBadMesh : public ::testing::TestWithParam<BadMeshCase> {};

TEST_P(ClothModelBadMesh, IsRejectedWithAMessageNamingTheElement) {
  TriangleMesh mesh = unitSquare();
  GetParam().spoil(mesh);
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr(GetParam().message));
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ClothModelBadMesh,
    ::testing::Values(
        BadMeshCase{"Empty", [](TriangleMesh& m) { m.indices.clear(); }, "mesh is empty"},
        BadMeshCase{"NotMultipleOfThree", [](TriangleMesh& m) { m.indices.pop_back(); },
                    "not a multiple of 3"},
        BadMeshCase{"OutOfRange", [](TriangleMesh& m) { m.indices[4] = 7; },
                    "triangle 1 (vertices 0, 7, 3): index 7 is out of range"},
        BadMeshCase{"RepeatedIndex", [](TriangleMesh& m) { m.indices[1] = 0; },
                    "triangle 0 (vertices 0, 0, 1): repeated vertex index 0"},
        BadMeshCase{"NaNPosition",
                    [](TriangleMesh& m) { m.positions[2].y() = std::numeric_limits<Real>::quiet_NaN(); },
                    "position of vertex 2"},
        BadMeshCase{"InfinitePosition",
                    [](TriangleMesh& m) { m.positions[3].x() = std::numeric_limits<Real>::infinity(); },
                    "position of vertex 3"},
        BadMeshCase{"ZeroArea", [](TriangleMesh& m) { m.positions[3] = Vec3(2, 2, 0); },
                    "triangle 1 (vertices 0, 1, 3): degenerate"},
        BadMeshCase{"Duplicate", [](TriangleMesh& m) { m.indices.insert(m.indices.end(), {1, 3, 0}); },
                    "triangle 2 (vertices 1, 3, 0): the same three vertices"},
        BadMeshCase{"UnusedVertex", [](TriangleMesh& m) { m.positions.push_back(Vec3(5, 5, 5)); },
                    "vertex 4 is used by no triangle"},
        BadMeshCase{"NonManifold",
                    [](TriangleMesh& m) {
                      m.positions.push_back(Vec3(0.5, 0.5, 1));
                      m.indices.insert(m.indices.end(), {0, 1, 4});
                    },
                    "edge (0, 1) is shared by triangles 0, 1 and 2: non-manifold"},
        BadMeshCase{"MaterialCoordinateCount",
                    [](TriangleMesh& m) { m.materialCoordinates = {Vec2(0, 0)}; },
                    "1 material coordinates for 4 vertices"}),
    [](const ::testing::TestParamInfo<BadMeshCase>& info) { return std::string(info.param.name); });

TEST(ClothModelMesh, NonManifoldAllowedWithoutBendingRequirement) {
  TriangleMesh mesh = unitSquare();
  mesh.positions.push_back(Vec3(0.5, 0.5, 1));
  mesh.indices.insert(mesh.indices.end(), {0, 1, 4});
  MeshSettings settings;
  settings.requireManifold = false;
  Result<ClothModel> model = ClothModel::fromMesh(mesh, settings);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->hinges().size(), 0u);  // the only interior edge is the non-manifold one
}

TEST(ClothModelObj, ReadsAFileWithQuadsAndUvs) {
  const std::string path = writeTemporaryFile("weft_square.obj",
                                              "# a unit square as one quad\n"
                                              "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                              "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                              "f 1/1 2/2 3/3 4/4\n");
  Result<ClothModel> model = ClothModel::loadObj(path);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->vertexCount(), 4u);
  EXPECT_EQ(model->triangleCount(), 2u);
  EXPECT_NEAR(model->totalArea(), 1.0, 1e-12);
}

TEST(ClothModelObj, UnreadableFileNamesThePath) {
  Result<ClothModel> model = ClothModel::loadObj("/nonexistent/weft/cloth.obj");
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("/nonexistent/weft/cloth.obj"));
  EXPECT_THAT(model.error().message, HasSubstr("check the path"));
}

TEST(ClothModelObj, OutOfRangeFaceIndexIsRejected) {
  const std::string path =
      writeTemporaryFile("weft_bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  Result<ClothModel> model = ClothModel::loadObj(path);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("weft_bad_index.obj"));
}

TEST(ClothModelObj, FileWithoutFacesIsRejected) {
  const std::string path = writeTemporaryFile("weft_no_faces.obj", "v 0 0 0\nv 1 0 0\n");
  Result<ClothModel> model = ClothModel::loadObj(path);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("no faces"));
}

}  // namespace
}  // namespace weft
