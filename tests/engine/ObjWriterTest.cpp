// OBJ export: a cloth's state written and read back through ClothModel::readObj() gives the same
// positions bit for bit and the same triangles; bad input and unwritable paths are errors.
#include <weft/engine/ObjWriter.h>
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace weft {
namespace {

using ::testing::HasSubstr;

TEST(ObjWriter, RoundTripsThroughReadObj) {
  GridSettings grid;
  grid.columns = 7;
  grid.rows = 5;
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  World world(WorldSettings{.threadCount = 1});
  const ClothId cloth = world.createCloth(model, ClothSettings{}).value();
  for (int frame = 0; frame < 5; ++frame) world.step(1.0 / 60.0);  // positions with long decimals
  const ClothRenderView view = world.renderView(cloth).value();
  ASSERT_FALSE(view.normals.empty());

  const std::string path = (std::filesystem::temp_directory_path() / "weft_export.obj").string();
  ASSERT_TRUE(writeObj(path, view, "frame 5\nsecond line").ok());
  Result<TriangleMesh> read = ClothModel::readObj(path);
  ASSERT_TRUE(read.ok()) << read.error().message;
  ASSERT_EQ(read->positions.size(), view.positions.size());
  // The writer prints round-trip precision and the reader parses correctly rounded: bitwise.
  for (std::size_t i = 0; i < view.positions.size(); ++i) {
    ASSERT_EQ(read->positions[i], view.positions[i]) << "vertex " << i;
  }
  EXPECT_EQ(read->indices, std::vector<Index>(view.indices.begin(), view.indices.end()));

  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  // The text itself is exact: a correctly rounded parse (std::from_chars) gives the same bits.
  std::istringstream lines(text.str());
  std::string line;
  std::size_t vertex = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("v ", 0) != 0) continue;
    const char* at = line.data() + 2;
    const char* end = line.data() + line.size();
    Vec3 parsed;
    for (int k = 0; k < 3; ++k) {
      while (at < end && *at == ' ') ++at;
      at = std::from_chars(at, end, parsed[k]).ptr;
    }
    ASSERT_EQ(parsed, view.positions[vertex]) << "vertex " << vertex;
    ++vertex;
  }
  EXPECT_EQ(vertex, view.positions.size());
  EXPECT_THAT(text.str(), HasSubstr("# frame 5\n# second line\nv "));
  EXPECT_THAT(text.str(), HasSubstr("\nvn "));
  EXPECT_THAT(text.str(), HasSubstr("\nf 1//1 "));
}

TEST(ObjWriter, RefusesBadMeshesAndUnwritablePaths) {
  const std::vector<Vec3> positions{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const std::vector<Index> triangle{0, 1, 2};
  Status status = writeObj("/nonexistent/weft/out.obj", positions, {}, triangle);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.error().message, HasSubstr("/nonexistent/weft/out.obj"));
  EXPECT_THAT(status.error().message, HasSubstr("folder exists"));

  EXPECT_THAT(formatObj(positions, {}, std::vector<Index>{0, 1, 3}).error().message, HasSubstr("uses vertex 3"));
  EXPECT_THAT(formatObj(positions, {}, std::vector<Index>{0, 1}).error().message, HasSubstr("multiple of three"));
  EXPECT_THAT(formatObj(positions, std::vector<Vec3>(2, Vec3::UnitZ()), triangle).error().message,
              HasSubstr("one per vertex"));
  std::vector<Vec3> bad = positions;
  bad[1].x() = std::nan("");
  EXPECT_THAT(formatObj(bad, {}, triangle).error().message, HasSubstr("vertex 1"));
  // Without normals, faces carry vertex indices only.
  EXPECT_EQ(formatObj(positions, {}, triangle).value(), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
}

TEST(ClothModelObj, ParsesTextFromMemory) {
  Result<TriangleMesh> mesh = ClothModel::parseObj("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n", "test square");
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  EXPECT_EQ(mesh->indices.size(), 6u);
  Result<TriangleMesh> bad = ClothModel::parseObj("v 0 0 0\nf 1 2 3\n", "test square");
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.error().message, HasSubstr("test square"));
}

}  // namespace
}  // namespace weft
