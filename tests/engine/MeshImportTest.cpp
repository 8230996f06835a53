// Meshes as content tools export them (issue 27, "Seams"): coincident vertices along UV seams
// are welded on import and the cloth then hangs and moves like one piece, with no intersecting
// pair and no frozen vertex; triangles wound against their neighbours are flipped and the model
// is the one the consistent mesh gives, bending included; a Möbius strip, a bowtie vertex and a
// weld that would collapse a triangle are refused, naming the elements.
#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

namespace weft {
namespace {

using ::testing::HasSubstr;

constexpr Index kColumns = 13, kRows = 11;  // 12 x 10 quads of 5 cm
constexpr Real kSpacing = 0.05;
constexpr Index kSeamColumn = 6;  // the UV seam runs down this column of vertices

// A hanging sheet in the xy-plane (row 0 at the bottom), each quad split along its rising
// diagonal, wound counter-clockwise seen from +z: vertex = row · kColumns + column.
TriangleMesh sheet() {
  TriangleMesh mesh;
  for (Index row = 0; row < kRows; ++row) {
    for (Index column = 0; column < kColumns; ++column) {
      mesh.positions.emplace_back(kSpacing * column, 1.0 + kSpacing * row, 0.0);
    }
  }
  for (Index row = 0; row + 1 < kRows; ++row) {
    for (Index column = 0; column + 1 < kColumns; ++column) {
      const Index v00 = row * kColumns + column, v01 = v00 + 1;
      const Index v10 = v00 + kColumns, v11 = v10 + 1;
      mesh.indices.insert(mesh.indices.end(), {v00, v01, v11, v00, v11, v10});
    }
  }
  return mesh;
}

// The sheet as an exporter writes it with two UV islands: every vertex of the seam column is
// written twice, and the triangles right of the seam use the copies.
TriangleMesh sheetWithUvSeam() {
  TriangleMesh mesh = sheet();
  std::vector<Index> copyOf(mesh.positions.size(), kInvalidIndex);
  for (Index row = 0; row < kRows; ++row) {
    const Index original = row * kColumns + kSeamColumn;
    copyOf[original] = Index(mesh.positions.size());
    mesh.positions.push_back(mesh.positions[original]);
  }
  for (std::size_t t = 0; t < mesh.indices.size() / 3; ++t) {
    // A triangle is right of the seam when one of its corners is.
    bool right = false;
    for (int k = 0; k < 3; ++k) right = right || mesh.indices[3 * t + k] % kColumns > kSeamColumn;
    if (!right) continue;
    for (int k = 0; k < 3; ++k) {
      Index& corner = mesh.indices[3 * t + k];
      if (copyOf[corner] != kInvalidIndex) corner = copyOf[corner];
    }
  }
  return mesh;
}

// Pins the top row, named as in the input mesh.
ClothSettings hangingByTheTopRow(const ClothModel& model) {
  ClothSettings settings;
  for (Index column = 0; column < kColumns; ++column) {
    settings.pinnedVertices.push_back(model.meshImport().modelVertex((kRows - 1) * kColumns + column));
  }
  return settings;
}

TEST(MeshImport, UvSeamIsWeldedAndTheCountReported) {
  const TriangleMesh mesh = sheetWithUvSeam();
  ASSERT_EQ(mesh.positions.size(), kColumns * kRows + kRows);
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, kRows);
  EXPECT_EQ(model->meshImport().flippedTriangles, 0u);
  EXPECT_EQ(model->meshImport().components, 1u);
  EXPECT_EQ(model->vertexCount(), kColumns * kRows);
  // The copies map onto their originals; the model is the seamless sheet's, element for element.
  for (Index row = 0; row < kRows; ++row) {
    EXPECT_EQ(model->meshImport().modelVertex(kColumns * kRows + row), row * kColumns + kSeamColumn);
  }
  const ClothModel seamless = ClothModel::fromMesh(sheet()).value();
  EXPECT_EQ(model->indices(), seamless.indices());
  EXPECT_EQ(model->hinges().size(), seamless.hinges().size());
  EXPECT_EQ(model->edges().size(), seamless.edges().size());
  EXPECT_TRUE(seamless.meshImport().modelVertexOfInput.empty());
}

TEST(MeshImport, NearlyCoincidentVerticesWeldWithinTheToleranceOnly) {
  TriangleMesh mesh = sheetWithUvSeam();
  const Real diagonal = std::hypot(kSpacing * (kColumns - 1), kSpacing * (kRows - 1));
  // One copy 0.4 tolerances away (welded), one 3 tolerances away (kept; its triangles then meet
  // the original only through the seam's other vertices).
  mesh.positions[kColumns * kRows + 2].x() += 0.4e-6 * diagonal;
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, kRows);
  mesh.positions[kColumns * kRows + 2].x() += 3e-6 * diagonal;
  model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, kRows - 1);
  // A larger tolerance takes it in again.
  MeshSettings wide;
  wide.weldTolerance = 1e-5;
  model = ClothModel::fromMesh(mesh, wide);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, kRows);
}

TEST(MeshImport, WeldingCanBeTurnedOff) {
  MeshSettings settings;
  settings.weldVertices = false;
  Result<ClothModel> model = ClothModel::fromMesh(sheetWithUvSeam(), settings);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, 0u);
  EXPECT_EQ(model->vertexCount(), kColumns * kRows + kRows);
  EXPECT_EQ(model->meshImport().components, 2u);  // the two islands
  settings.weldVertices = true;
  settings.weldTolerance = 0;
  EXPECT_EQ(ClothModel::fromMesh(sheetWithUvSeam(), settings)->vertexCount(), kColumns * kRows + kRows);
}

// Runs the hanging sheet in a gust for `frames` frames of 1/60 s. Every frame: no intersecting
// triangle pair (exact test, touching counts), no frozen vertex, no rollback, retry or
// instability.
void expectHangsFreely(const std::shared_ptr<const ClothModel>& model, const ClothSettings& settings,
                       int frames) {
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  World world(worldSettings);
  const ClothId cloth = world.createCloth(model, settings).value();
  // A gust across the sheet, so it moves out of its plane.
  ASSERT_TRUE(world.setWind(Vec3(0, 0, 4)).ok());
  SelfIntersectionCounter counter =
      SelfIntersectionCounter::create(model->indices(), model->restPositions()).value();
  const Index bottomMiddle = model->meshImport().modelVertex(kSeamColumn);
  const Vec3 start = world.positions(cloth).value()[bottomMiddle];
  Real travel = 0;
  for (int frame = 1; frame <= frames; ++frame) {
    const StepStatus status = world.step(1.0 / 60.0);
    ASSERT_FALSE(hasFlag(status, StepStatus::RolledBack) ||
                 hasFlag(status, StepStatus::RetriedWithSmallerStep) ||
                 hasFlag(status, StepStatus::Unstable))
        << "frame " << frame << ": " << describe(status);
    ASSERT_EQ(world.stats().frozenVertices, 0u) << "frame " << frame;
    ASSERT_EQ(counter.count(world.positions(cloth).value()), 0u) << "frame " << frame;
    travel = std::max(travel, (world.positions(cloth).value()[bottomMiddle] - start).norm());
  }
  // The wind carries the bottom of the seam out of the plane: the sheet is not frozen in place.
  EXPECT_GT(travel, 0.05);
}

TEST(MeshImport, AWeldedSeamHangsAndMovesWithoutIntersectionsOrFrozenVertices) {
  const TriangleMesh mesh = sheetWithUvSeam();
  auto model = std::make_shared<const ClothModel>(ClothModel::fromMesh(mesh).value());
  expectHangsFreely(model, hangingByTheTopRow(*model), 90);
}

TEST(MeshImport, AnUnweldedSeamIsTwoBordersTouchingEverywhere) {
  // What the weld prevents: kept apart, the seam's two borders lie on each other, and the exact
  // test counts their triangles as intersecting from the first frame.
  MeshSettings settings;
  settings.weldVertices = false;
  const ClothModel model = ClothModel::fromMesh(sheetWithUvSeam(), settings).value();
  SelfIntersectionCounter counter =
      SelfIntersectionCounter::create(model.indices(), model.restPositions()).value();
  EXPECT_GT(counter.count(model.restPositions()), 0u);
}

TEST(MeshImport, SeamWithMaterialCoordinatesKeepsEachIslandsLayout) {
  TriangleMesh mesh = sheetWithUvSeam();
  // Each island's own (u, v) in metres; the right one shifted by 1 m along u, as a UV layout
  // places islands apart. The seam's copies take the right island's coordinates.
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3& x = mesh.positions[i];
    const bool rightIsland = i >= kColumns * kRows || i % kColumns > kSeamColumn;
    mesh.materialCoordinates.emplace_back(x.x() + (rightIsland ? 1.0 : 0.0), x.y());
  }
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, kRows);
  // Every triangle keeps its rest shape: the same areas as the seamless sheet.
  const ClothModel seamless = ClothModel::fromMesh(sheet()).value();
  EXPECT_NEAR(model->totalArea(), seamless.totalArea(), 1e-12);
  for (std::size_t t = 0; t < model->triangles().size(); ++t) {
    EXPECT_NEAR(model->triangles()[t].area, seamless.triangles()[t].area, 1e-15) << t;
  }
  auto shared = std::make_shared<const ClothModel>(std::move(model).value());
  expectHangsFreely(shared, hangingByTheTopRow(*shared), 30);
}

TEST(MeshImport, AWeldThatCollapsesATriangleIsRefused) {
  TriangleMesh mesh = sheet();
  // Vertex 14 moved to within the tolerance of vertex 0: triangle 0 (0, 1, 14) would collapse.
  mesh.positions[14] = mesh.positions[0] + Vec3(1e-9, 0, 0);
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("triangle 0 (vertices 0, 1, 14)"));
  EXPECT_THAT(model.error().message, HasSubstr("weldTolerance"));
}

TEST(MeshImport, ADoubleSidedCopyIsRefusedAfterWelding) {
  TriangleMesh mesh = sheet();
  // The back side: every vertex again, every triangle again with the winding reversed.
  const Index n = Index(mesh.positions.size());
  const std::size_t triangles = mesh.indices.size() / 3;
  for (Index i = 0; i < n; ++i) mesh.positions.push_back(mesh.positions[i]);
  for (std::size_t t = 0; t < triangles; ++t) {
    mesh.indices.insert(mesh.indices.end(), {mesh.indices[3 * t] + n, mesh.indices[3 * t + 2] + n,
                                             mesh.indices[3 * t + 1] + n});
  }
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("the same three vertices form triangle 0"));
  EXPECT_THAT(model.error().message, HasSubstr("welded"));
}

TEST(MeshImport, BadWeldToleranceIsRefused) {
  for (Real tolerance : {-1e-6, 1.0, std::numeric_limits<Real>::quiet_NaN()}) {
    MeshSettings settings;
    settings.weldTolerance = tolerance;
    EXPECT_THAT(ClothModel::fromMesh(sheet(), settings).error().message,
                HasSubstr("MeshSettings::weldTolerance"));
  }
}

// ------------------------------------------------------------------------------ winding

// A quarter cylinder (curved rest shape, so the isometric stencils hold rest curvatures that
// depend on the normals), wound consistently.
TriangleMesh curvedSheet() {
  TriangleMesh mesh = sheet();
  for (Vec3& x : mesh.positions) {
    const Real angle = x.x() / 0.6;  // radius 0.6 m
    x = Vec3(0.6 * std::sin(angle), x.y(), 0.6 * (1 - std::cos(angle)));
  }
  return mesh;
}

TEST(MeshImport, AFlippedTriangleIsFlippedBackAndTheModelIsTheConsistentOnes) {
  const TriangleMesh consistent = curvedSheet();
  TriangleMesh mesh = consistent;
  const std::size_t flipped = 37;
  std::swap(mesh.indices[3 * flipped + 1], mesh.indices[3 * flipped + 2]);
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().flippedTriangles, 1u);
  const ClothModel reference = ClothModel::fromMesh(consistent).value();
  EXPECT_EQ(model->indices(), reference.indices());
  // Bending uses the consistent orientation: stencils and hinges as for the consistent mesh.
  ASSERT_EQ(model->bendingStencils().size(), reference.bendingStencils().size());
  for (std::size_t k = 0; k < reference.bendingStencils().size(); ++k) {
    EXPECT_EQ(model->bendingStencils()[k].restCurvature, reference.bendingStencils()[k].restCurvature) << k;
  }
  ASSERT_EQ(model->bendingWeights().size(), reference.bendingWeights().size());
  for (std::size_t k = 0; k < reference.bendingWeights().size(); ++k) {
    EXPECT_EQ(model->bendingWeights()[k].weight, reference.bendingWeights()[k].weight) << k;
  }
  ASSERT_EQ(model->hinges().size(), reference.hinges().size());
  for (std::size_t k = 0; k < reference.hinges().size(); ++k) {
    EXPECT_EQ(model->hinges()[k].vertices, reference.hinges()[k].vertices) << k;
    EXPECT_EQ(model->hinges()[k].restAngle, reference.hinges()[k].restAngle) << k;
  }
}

TEST(MeshImport, EachPieceTakesTheWindingOfItsFirstTriangle) {
  // Two separate sheets; the second is wound the other way throughout, which is consistent
  // within it: nothing is flipped.
  TriangleMesh mesh = sheet();
  const TriangleMesh other = sheet();
  const Index n = Index(mesh.positions.size());
  for (const Vec3& x : other.positions) mesh.positions.push_back(x + Vec3(0, 0, 1));
  for (std::size_t t = 0; t < other.indices.size() / 3; ++t) {
    mesh.indices.insert(mesh.indices.end(), {other.indices[3 * t] + n, other.indices[3 * t + 2] + n,
                                             other.indices[3 * t + 1] + n});
  }
  // Then the second piece's triangles but its first are reversed: all of them but one flip back.
  std::vector<Index> reversed = mesh.indices;
  const std::size_t first = other.indices.size() / 3;  // index of the second piece's first triangle
  for (std::size_t t = first + 1; t < mesh.indices.size() / 3; ++t) {
    std::swap(reversed[3 * t + 1], reversed[3 * t + 2]);
  }
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().components, 2u);
  EXPECT_EQ(model->meshImport().flippedTriangles, 0u);
  TriangleMesh spoiled = mesh;
  spoiled.indices = reversed;
  model = ClothModel::fromMesh(spoiled);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().flippedTriangles, mesh.indices.size() / 3 - first - 1);
  EXPECT_EQ(model->indices(), mesh.indices);
}

TEST(MeshImport, InconsistentWindingIsAnErrorWhenFixingIsOff) {
  TriangleMesh mesh = sheet();
  std::swap(mesh.indices[3 * 5 + 1], mesh.indices[3 * 5 + 2]);
  MeshSettings settings;
  settings.fixWinding = false;
  Result<ClothModel> model = ClothModel::fromMesh(mesh, settings);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("and 5 run edge"));
  EXPECT_THAT(model.error().message, HasSubstr("MeshSettings::fixWinding"));
  EXPECT_TRUE(ClothModel::fromMesh(sheet(), settings).ok());
}

// A band of `segments` quads around a circle. Twisted: the cross-section turns half a turn on
// the way round (a Möbius strip), so the last quad joins the first with its sides swapped.
TriangleMesh band(Index segments, bool twisted) {
  TriangleMesh mesh;
  const Real radius = 0.5, halfWidth = 0.1;
  for (Index i = 0; i < segments; ++i) {
    const Real angle = 2 * std::numbers::pi * i / segments;
    const Vec3 centre(radius * std::cos(angle), radius * std::sin(angle), 0);
    const Vec3 radial(std::cos(angle), std::sin(angle), 0);
    const Real turn = twisted ? angle / 2 : std::numbers::pi / 2;
    const Vec3 across = std::cos(turn) * radial + std::sin(turn) * Vec3::UnitZ();
    mesh.positions.push_back(centre - halfWidth * across);  // 2i: one side
    mesh.positions.push_back(centre + halfWidth * across);  // 2i + 1: the other
  }
  for (Index i = 0; i < segments; ++i) {
    const Index a0 = 2 * i, b0 = 2 * i + 1;
    const bool swapped = twisted && i + 1 == segments;
    const Index next = (i + 1) % segments;
    const Index a1 = swapped ? 2 * next + 1 : 2 * next, b1 = swapped ? 2 * next : 2 * next + 1;
    mesh.indices.insert(mesh.indices.end(), {a0, a1, b1, a0, b1, b0});
  }
  return mesh;
}

TEST(MeshImport, AMoebiusStripIsRefusedNamingTheTriangles) {
  Result<ClothModel> model = ClothModel::fromMesh(band(24, /*twisted=*/true));
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("non-orientable (a Möbius strip)"));
  EXPECT_THAT(model.error().message,
              ::testing::ContainsRegex("triangles [0-9]+ and [0-9]+ across edge \\([0-9]+, [0-9]+\\) "
                                       "cannot be wound consistently"));
  // The same band without its twist is orientable, and nothing in it is flipped.
  Result<ClothModel> ring = ClothModel::fromMesh(band(24, /*twisted=*/false));
  ASSERT_TRUE(ring.ok()) << ring.error().message;
  EXPECT_EQ(ring->meshImport().flippedTriangles, 0u);
}

// ------------------------------------------------------------------------------ bowties

// Two fans sharing vertex 0 only: the corners of two triangles touching at a point.
TriangleMesh bowtie() {
  TriangleMesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(-0.1, 0.1, 0), Vec3(-0.1, -0.1, 0), Vec3(0.1, 0.1, 0),
                    Vec3(0.1, -0.1, 0), Vec3(-0.2, 0, 0)};
  mesh.indices = {0, 1, 2, 0, 4, 3, 1, 5, 2};
  return mesh;
}

TEST(MeshImport, ABowtieVertexIsRefusedNamingIt) {
  Result<ClothModel> model = ClothModel::fromMesh(bowtie());
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, HasSubstr("vertex 0 is a bowtie: triangles 0 and 1"));
  EXPECT_THAT(model.error().message, HasSubstr("MeshSettings::requireManifold"));
}

TEST(MeshImport, ABowtieAllowedWithoutTheManifoldRequirementHasNoStencilAndSimulatesFinitely) {
  MeshSettings settings;
  settings.requireManifold = false;
  Result<ClothModel> model = ClothModel::fromMesh(bowtie(), settings);
  ASSERT_TRUE(model.ok()) << model.error().message;
  // Two fans that meet at a point pass no bending moment: the bowtie vertex has no stencil.
  bool bowtieBends = false, otherBends = false;
  for (const BendingStencil& stencil : model->bendingStencils()) {
    bowtieBends = bowtieBends || stencil.vertex == 0;
    otherBends = otherBends || stencil.vertex == 2;
  }
  EXPECT_FALSE(bowtieBends);
  EXPECT_TRUE(otherBends);
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  World world(worldSettings);
  ClothSettings cloth;
  cloth.pinnedVertices = {1, 5};
  const ClothId id = world.createCloth(std::make_shared<const ClothModel>(std::move(model).value()), cloth).value();
  for (int frame = 0; frame < 120; ++frame) {
    const StepStatus status = world.step(1.0 / 60.0);
    ASSERT_FALSE(hasFlag(status, StepStatus::RolledBack)) << frame << ": " << describe(status);
    ASSERT_FALSE(hasFlag(status, StepStatus::Unstable)) << frame << ": " << describe(status);
  }
  for (const Vec3& x : world.positions(id).value()) EXPECT_TRUE(x.allFinite());
  // The far fan hangs from the near one by the shared vertex: it swung down.
  const std::span<const Vec3> x = world.positions(id).value();
  EXPECT_LT(0.5 * (x[3].y() + x[4].y()), -0.05);
}

// ------------------------------------------------------------------------------ OBJ files

TEST(MeshImport, AnObjWithAUvSeamIsWeldedOnLoad) {
  // The sheet of 2 x 1 quads written with its middle column twice (two texture islands).
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "weft_seam.obj";
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"   // left island 1..4
                         "v 1 0 0\nv 2 0 0\nv 1 1 0\nv 2 1 0\n"   // right island 5..8
                         "vt 0 0\nvt 0.5 0\nvt 0 1\nvt 0.5 1\nvt 0.5 0\nvt 1 0\nvt 0.5 1\nvt 1 1\n"
                         "f 1/1 2/2 4/4 3/3\nf 5/5 6/6 8/8 7/7\n";
  Result<ClothModel> model = ClothModel::loadObj(path.string());
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(model->meshImport().weldedVertices, 2u);
  EXPECT_EQ(model->vertexCount(), 6u);
  EXPECT_EQ(model->meshImport().modelVertex(4), model->meshImport().modelVertex(1));
  EXPECT_EQ(model->meshImport().components, 1u);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace weft
