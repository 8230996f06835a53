// Golden hashes of the shipped scene files (scenes/data/*.json), run the way `weft run` runs
// them: a ScriptedScene on the world's default threads (all cores; the determinism contract
// makes the count irrelevant to the bits), stepped for the file's own run length ("run.frames").
// Key: "scene-file/<file>/<frames>-frames". Every file in the folder is covered: a new scene
// needs its key added (tools/update-golden-hashes), not a new test.
//
// The rod scene (rod-hang.json: a towel hanging on a rod by its faces) is also run for 30 s, the
// span over which it must hang still, as "rod/rod-hang.json/1800-frames".
#include "golden/GoldenHashes.h"

#include <weft/scenes/SceneFile.h>
#include <weft/scenes/ScriptedScene.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>
#include <vector>

namespace weft {
namespace {

const std::string kSceneDir = WEFT_SCENE_DATA_DIR;

std::vector<std::string> shippedSceneFiles() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(kSceneDir)) {
    if (entry.path().extension() == ".json") files.push_back(entry.path().filename().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Runs a scene file for `frames` frames (0: its own run length); returns the final state hash.
std::uint64_t runSceneFile(const std::string& file, Index frames = 0) {
  Result<SceneDescription> description = loadSceneFile(kSceneDir + "/" + file);
  EXPECT_TRUE(description.ok()) << description.error().message;
  if (!description.ok()) return 0;
  if (frames == 0) frames = description->frames;
  Result<ScriptedScene> created = ScriptedScene::create(std::move(description).value());
  EXPECT_TRUE(created.ok()) << created.error().message;
  if (!created.ok()) return 0;
  ScriptedScene& scene = created.value();
  const std::uint64_t start = scene.world().stateHash();
  for (Index frame = 0; frame < frames; ++frame) scene.stepFrame();
  EXPECT_EQ(scene.frame(), frames);
  const std::uint64_t end = scene.world().stateHash();
  EXPECT_NE(start, end) << file << ": the state never moved";
  return end;
}

class ShippedSceneFile : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedSceneFile, EndsInItsGoldenStateHash) {
  const std::string& file = GetParam();
  Result<SceneDescription> description = loadSceneFile(kSceneDir + "/" + file);
  ASSERT_TRUE(description.ok()) << description.error().message;
  const Index frames = description->frames;
  test::expectGoldenHash("scene-file/" + file + "/" + std::to_string(frames) + "-frames",
                         runSceneFile(file));
}

INSTANTIATE_TEST_SUITE_P(Shipped, ShippedSceneFile, ::testing::ValuesIn(shippedSceneFiles()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = std::filesystem::path(info.param).stem().string();
                           for (char& c : name) c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
                           return name;
                         });

TEST(RodScene, EndsThirtySecondsInItsGoldenStateHash) {
  test::expectGoldenHash("rod/rod-hang.json/1800-frames", runSceneFile("rod-hang.json", 1800));
}

}  // namespace
}  // namespace weft
