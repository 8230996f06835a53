// Scene files: every shipped scene loads, validates and builds; the format's defaults and
// selections do what the format document says; every kind of mistake is reported at its JSON
// path with a fix, several mistakes at once.
#include <weft/engine/FabricPresets.h>
#include <weft/scenes/SceneFile.h>
#include <weft/scenes/ScriptedScene.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace weft {
namespace {

using ::testing::HasSubstr;

const std::string kSceneDir = WEFT_SCENE_DATA_DIR;

TEST(SceneFile, EveryShippedSceneLoadsBuildsAndSteps) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(kSceneDir)) {
    if (entry.path().extension() == ".json") names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  // The curtain, the shared scenes of the collision issue, and the banner (attachments, wind).
  EXPECT_EQ(names, (std::vector<std::string>{"banner", "curtain", "floor-fold", "projectile",
                                             "rod-hang", "rotating-sphere", "sphere-drop",
                                             "two-layers"}));
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    Result<SceneDescription> scene = loadSceneFile(kSceneDir + "/" + name + ".json");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    EXPECT_EQ(scene->name, name);
    EXPECT_FALSE(scene->description.empty());
    ScriptedSceneSettings settings;
    settings.threadCount = 1;
    Result<ScriptedScene> built = ScriptedScene::create(std::move(scene).value(), settings);
    ASSERT_TRUE(built.ok()) << built.error().message;
    EXPECT_EQ(built->stepFrame(), StepStatus::Ok);
    EXPECT_EQ(built->frame(), 1u);
  }
}

TEST(SceneFile, FaceContactsAndTheJointProjectionCanBeTurnedOffPerCloth) {
  for (const std::string key : {"faceContacts", "jointContactProjection"}) {
    SCOPED_TRACE(key);
    Result<SceneDescription> scene = loadSceneText(
        R"({"version": 1, "cloths": [{"grid": {}, ")" + key + R"(": false}]})");
    ASSERT_TRUE(scene.ok()) << scene.error().message;
    const ClothSettings& settings = scene->cloths[0].settings;
    EXPECT_FALSE(key == "faceContacts" ? settings.faceContacts : settings.jointContactProjection);
    Result<SceneDescription> wrong = loadSceneText(
        R"({"version": 1, "cloths": [{"grid": {}, ")" + key + R"(": "no"}]})");
    ASSERT_FALSE(wrong.ok());
    EXPECT_THAT(wrong.error().message, HasSubstr("/cloths/0/" + key));
  }
  // Both on unless a file says otherwise.
  Result<SceneDescription> plain = loadSceneText(R"({"version": 1, "cloths": [{"grid": {}}]})");
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->cloths[0].settings.faceContacts);
  EXPECT_TRUE(plain->cloths[0].settings.jointContactProjection);
}

TEST(SceneFile, DefaultsAreTheDocumentedOnes) {
  Result<SceneDescription> scene = loadSceneText(R"({"version": 1, "cloths": [{"grid": {}}]})");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->frames, 600u);
  EXPECT_EQ(scene->frameDt, 1.0 / 60.0);
  EXPECT_EQ(scene->gravity, Vec3(0, -9.81, 0));
  ASSERT_EQ(scene->cloths.size(), 1u);
  const ClothDescription& cloth = scene->cloths[0];
  EXPECT_EQ(cloth.model->vertexCount(), 41u * 31u);  // the curtain's grid
  EXPECT_EQ(cloth.settings.material.arealDensity, ClothMaterial{}.arealDensity);
  EXPECT_EQ(cloth.settings.solver.integrator, IntegratorKind::ImplicitEuler);
  EXPECT_TRUE(cloth.settings.selfCollision);
  EXPECT_TRUE(cloth.settings.faceContacts);
  EXPECT_TRUE(cloth.settings.pinnedVertices.empty());
  EXPECT_TRUE(scene->colliders.empty());
}

TEST(SceneFile, PresetThenFieldsOverrideIt) {
  Result<SceneDescription> scene = loadSceneText(R"({"version": 1, "cloths": [{"grid": {},
      "material": {"preset": "denim", "friction": 0.7},
      "solver": {"integrator": "rk4", "substeps": 12, "pinTeleportDistance": 0,
                 "cgStopping": "relativeResidual", "tightCgTolerance": 1e-4,
                 "tightSelfContactDensity": 0.1, "tightPinTravel": 2},
      "forceModel": "mass-spring"}]})");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  const ClothSettings& settings = scene->cloths[0].settings;
  EXPECT_EQ(settings.material.arealDensity, denimFabric().arealDensity);
  EXPECT_EQ(settings.material.friction, 0.7);
  EXPECT_EQ(settings.solver.integrator, IntegratorKind::RungeKutta4);
  EXPECT_EQ(settings.solver.substeps, 12u);
  EXPECT_EQ(settings.solver.pinTeleportDistance, 0.0);
  EXPECT_EQ(settings.solver.cgStopping, PcgStopping::RelativeResidual);
  EXPECT_EQ(settings.solver.tightCgTolerance, 1e-4);
  EXPECT_EQ(settings.solver.tightSelfContactDensity, 0.1);
  EXPECT_EQ(settings.solver.tightPinTravel, 2.0);
  EXPECT_EQ(settings.forceModel, ForceModel::MassSpring);
}

TEST(SceneFile, RowAndColumnSelectGridLines) {
  // A 4 × 3 grid: vertex = row · 4 + column.
  Result<SceneDescription> scene = loadSceneText(R"({"version": 1, "cloths": [
      {"grid": {"columns": 4, "rows": 3}, "pins": [{"row": 2}, {"vertices": [0]}]},
      {"grid": {"columns": 4, "rows": 3}, "pins": [{"column": 1}]}]})");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->cloths[0].settings.pinnedVertices, (std::vector<Index>{8, 9, 10, 11, 0}));
  EXPECT_EQ(scene->cloths[1].settings.pinnedVertices, (std::vector<Index>{1, 5, 9}));
  ASSERT_EQ(scene->cloths[0].pins.size(), 2u);
  EXPECT_EQ(scene->cloths[0].pins[1].vertices, (std::vector<Index>{0}));

  // Row 2 and column 0 share vertex 8: pinned twice is an error naming both groups.
  scene = loadSceneText(R"({"version": 1, "cloths": [{
      "grid": {"columns": 4, "rows": 3}, "pins": [{"row": 2}, {"column": 0}]}]})");
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.error().message,
              HasSubstr("/cloths/0/pins/1: vertex 8 is already pinned by /cloths/0/pins/0"));
}

TEST(SceneFile, MeshClothsComeFromObjFilesBesideTheScene) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "weft_scene_mesh";
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "square.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  std::ofstream(folder / "scene.json")
      << R"({"version": 1, "cloths": [{"mesh": {"obj": "square.obj"}, "pins": [{"vertices": [2, 3]}]}],
            "colliders": [{"type": "mesh", "obj": "square.obj", "position": [0, -1, 0]}]})";
  Result<SceneDescription> scene = loadSceneFile((folder / "scene.json").string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->cloths[0].model->triangleCount(), 2u);
  EXPECT_EQ(scene->cloths[0].settings.pinnedVertices, (std::vector<Index>{2, 3}));
  EXPECT_TRUE(std::holds_alternative<TriangleMeshShape>(scene->colliders[0].shape));
  EXPECT_EQ(scene->name, "scene");
}

// One mistake per case: the scene text, the JSON path the error must name, and a piece of the fix.
struct BadScene {
  const char* name;
  const char* json;
  const char* path;
  const char* fix;
};

class SceneFileErrors : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneFileErrors, NameThePathAndTheFix) {
  SceneLoadOptions options;
  options.baseDirectory = std::filesystem::temp_directory_path().string();
  SceneParseOutcome outcome = parseSceneText(GetParam().json, options);
  ASSERT_FALSE(outcome.scene.has_value());
  ASSERT_FALSE(outcome.issues.empty());
  const std::string text = formatIssues(outcome.issues);
  EXPECT_THAT(text, HasSubstr(std::string(GetParam().path) + ": ")) << text;
  EXPECT_THAT(text, HasSubstr(GetParam().fix)) << text;
  // The Result form carries the same lines.
  Result<SceneDescription> result = loadSceneText(GetParam().json, options);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.error().message, text);
}

#define CLOTH(extra) R"({"version": 1, "cloths": [{"grid": {"columns": 3, "rows": 3})" extra "}]}"

INSTANTIATE_TEST_SUITE_P(
    Cases, SceneFileErrors,
    ::testing::Values(
        BadScene{"MalformedJson", R"({"version": 1, "cloths": [)", "/", "malformed JSON"},
        BadScene{"NotAnObject", "[1, 2]", "/", "must hold a JSON object"},
        BadScene{"MissingVersion", R"({"cloths": [{"grid": {}}]})", "/version", "\"version\": 1"},
        BadScene{"MissingCloths", R"({"version": 1})", "/cloths", "is missing"},
        BadScene{"NoCloths", R"({"version": 1, "cloths": []})", "/cloths", "at least one cloth"},
        BadScene{"UnknownTopLevelKey", R"({"version": 1, "cloth": [], "cloths": [{"grid": {}}]})",
                 "/cloth", "allowed here: version, name"},
        BadScene{"WrongTypeFrames", R"({"version": 1, "run": {"frames": "ten"}, "cloths": [{"grid": {}}]})",
                 "/run/frames", "must be a whole number"},
        BadScene{"FractionalFrames", R"({"version": 1, "run": {"frames": 2.5}, "cloths": [{"grid": {}}]})",
                 "/run/frames", "whole number"},
        BadScene{"BothRates", R"({"version": 1, "run": {"frameDt": 0.01, "framesPerSecond": 60}, "cloths": [{"grid": {}}]})",
                 "/run/frameDt", "not both"},
        BadScene{"NegativeDensity", CLOTH(R"(, "material": {"arealDensity": -0.15})"),
                 "/cloths/0/material/arealDensity", "must be greater than 0 (kg/m²)"},
        BadScene{"MisspelledMaterialKey", CLOTH(R"(, "material": {"arealDensty": 0.2})"),
                 "/cloths/0/material/arealDensty", "allowed here: preset, arealDensity"},
        BadScene{"UnknownPreset", CLOTH(R"(, "material": {"preset": "velvet"})"),
                 "/cloths/0/material/preset", "choose one of: cotton, wool"},
        BadScene{"UnknownIntegrator", CLOTH(R"(, "solver": {"integrator": "verlet"})"),
                 "/cloths/0/solver/integrator", "implicit-euler"},
        BadScene{"UnknownCgStopping", CLOTH(R"(, "solver": {"cgStopping": "energy"})"),
                 "/cloths/0/solver/cgStopping", "relativeResidual, velocityError"},
        BadScene{"NegativeTightCgTolerance", CLOTH(R"(, "solver": {"tightCgTolerance": -1e-3})"),
                 "/cloths/0/solver/tightCgTolerance", "must not be negative"},
        BadScene{"ZeroTightSelfContactDensity", CLOTH(R"(, "solver": {"tightSelfContactDensity": 0})"),
                 "/cloths/0/solver/tightSelfContactDensity", "greater than 0 (self-contacts per vertex)"},
        BadScene{"NegativeTeleportDistance", CLOTH(R"(, "solver": {"pinTeleportDistance": -1})"),
                 "/cloths/0/solver/pinTeleportDistance", "cloth sizes"},
        BadScene{"WrongVectorLength", CLOTH(R"(, "translation": [1, 2])"),
                 "/cloths/0/translation", "three numbers"},
        BadScene{"VertexOutOfRange", CLOTH(R"(, "pins": [{"vertices": [0, 9]}])"),
                 "/cloths/0/pins/0/vertices/1", "from 0 to 8"},
        BadScene{"RowOutOfRange", CLOTH(R"(, "pins": [{"row": 3}])"), "/cloths/0/pins/0/row", "from 0 to 2"},
        BadScene{"PinSelectsNothing", CLOTH(R"(, "pins": [{"script": {"keyframes": [{"time": 0}]}}])"),
                 "/cloths/0/pins/0", "give one of \"vertices\""},
        BadScene{"KeyframesGoBack", CLOTH(R"(, "pins": [{"row": 0, "script": {"keyframes": [{"time": 1}, {"time": 0.5}]}}])"),
                 "/cloths/0/pins/0/script/keyframes/1/time", "must increase"},
        BadScene{"UnknownEasing", CLOTH(R"(, "pins": [{"row": 0, "script": {"easing": "cubic", "keyframes": [{"time": 0}]}}])"),
                 "/cloths/0/pins/0/script/easing", "\"linear\" or \"smoothstep\""},
        BadScene{"GridAndMesh", R"({"version": 1, "cloths": [{"grid": {}, "mesh": {"obj": "a.obj"}}]})",
                 "/cloths/0", "not both"},
        BadScene{"TooSmallGrid", R"({"version": 1, "cloths": [{"grid": {"columns": 1}}]})",
                 "/cloths/0/grid/columns", "from 2 to"},
        BadScene{"UnreadableObj", R"({"version": 1, "cloths": [{"mesh": {"obj": "weft_no_such_file.obj"}}]})",
                 "/cloths/0/mesh/obj", "cannot read OBJ file"},
        BadScene{"RowOnMesh", R"({"version": 1, "cloths": [{"mesh": {"obj": "weft_no_such_file.obj"}, "pins": [{"row": 0}]}]})",
                 "/cloths/0/pins", "could not be built"},
        BadScene{"ColliderWithoutType", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"radius": 1}]})",
                 "/colliders/0/type", "\"sphere\""},
        BadScene{"NegativeRadius", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"type": "sphere", "radius": -1}]})",
                 "/colliders/0/radius", "greater than 0 (m)"},
        BadScene{"PlaneWithRadius", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"type": "plane", "normal": [0, 1, 0], "radius": 1}]})",
                 "/colliders/0/radius", "unknown key"},
        BadScene{"ZeroNormal", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"type": "plane", "normal": [0, 0, 0]}]})",
                 "/colliders/0/normal", "zero vector"},
        BadScene{"VelocityAndKeyframes", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"type": "sphere", "radius": 1, "linearVelocity": [1, 0, 0], "motion": {"keyframes": [{"time": 0}]}}]})",
                 "/colliders/0/motion", "keyframes set the velocities"},
        BadScene{"UnreadableColliderObj", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"type": "mesh", "obj": "weft_no_such_file.obj"}]})",
                 "/colliders/0/obj", "cannot read OBJ file"},
        BadScene{"BadResolution", R"({"version": 1, "camera": {"resolution": [0, 720]}, "cloths": [{"grid": {}}]})",
                 "/camera/resolution/0", "from 16 to 16384"},
        BadScene{"AttachToUnknownCollider", R"({"version": 1, "cloths": [{"grid": {"columns": 3, "rows": 3}, "pins": [{"row": 2, "attachTo": "rod"}]}], "colliders": [{"type": "sphere", "name": "ball", "radius": 1}]})",
                 "/cloths/0/pins/0/attachTo", "give one of \"ball\""},
        BadScene{"AttachToWithoutColliders", CLOTH(R"(, "pins": [{"row": 2, "attachTo": "rod"}])"),
                 "/cloths/0/pins/0/attachTo", "the scene has no colliders"},
        BadScene{"AttachToAndScript", R"({"version": 1, "cloths": [{"grid": {"columns": 3, "rows": 3}, "pins": [{"row": 2, "attachTo": "ball", "script": {"keyframes": [{"time": 0}]}}]}], "colliders": [{"type": "sphere", "name": "ball", "radius": 1}]})",
                 "/cloths/0/pins/0/attachTo", "remove \"script\" or \"attachTo\""},
        BadScene{"WindKeyframesGoBack", R"({"version": 1, "world": {"windScript": {"keyframes": [{"time": 1, "wind": [0, 0, 1]}, {"time": 1}]}}, "cloths": [{"grid": {}}]})",
                 "/world/windScript/keyframes/1/time", "must increase"},
        BadScene{"WindNotAVector", R"({"version": 1, "world": {"windScript": {"keyframes": [{"time": 0, "wind": 3}]}}, "cloths": [{"grid": {}}]})",
                 "/world/windScript/keyframes/0/wind", "three numbers"},
        BadScene{"EscapedKey", R"({"version": 1, "a/b~c": 1, "cloths": [{"grid": {}}]})", "/a~1b~0c", "unknown key"}),
    [](const ::testing::TestParamInfo<BadScene>& info) { return std::string(info.param.name); });

TEST(SceneFile, ReportsEveryMistakeAtOnce) {
  SceneParseOutcome outcome = parseSceneText(R"({"version": 1, "run": {"frames": -1},
      "cloths": [{"grid": {}, "material": {"arealDensity": 0, "thickness": "thin"}}]})");
  ASSERT_EQ(outcome.issues.size(), 3u) << formatIssues(outcome.issues);
  EXPECT_EQ(outcome.issues[0].path, "/run/frames");
  EXPECT_EQ(outcome.issues[1].path, "/cloths/0/material/arealDensity");
  EXPECT_EQ(outcome.issues[2].path, "/cloths/0/material/thickness");
}

TEST(SceneFile, UnreadableSceneFileNamesIt) {
  SceneParseOutcome outcome = parseSceneFile("/nonexistent/weft/scene.json");
  ASSERT_EQ(outcome.issues.size(), 1u);
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("/nonexistent/weft/scene.json"));
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("check the path"));
  outcome = parseSceneFile(std::filesystem::temp_directory_path().string());
  ASSERT_EQ(outcome.issues.size(), 1u);
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("is a directory"));
}

TEST(SceneFile, OversizedGridsAreRefusedBeforeTheyAreBuilt) {
  SceneLoadOptions options;
  options.maxVerticesPerCloth = 100;
  SceneParseOutcome outcome = parseSceneText(R"({"version": 1, "cloths": [{"grid": {"columns": 11, "rows": 10}}]})", options);
  ASSERT_EQ(outcome.issues.size(), 1u);
  EXPECT_EQ(outcome.issues[0].path, "/cloths/0/grid");
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("limit of 100"));
}

TEST(SceneFile, IntegratorNamesRoundTrip) {
  for (IntegratorKind kind : {IntegratorKind::ExplicitEuler, IntegratorKind::SymplecticEuler,
                              IntegratorKind::Midpoint, IntegratorKind::RungeKutta4,
                              IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2}) {
    EXPECT_EQ(integratorFromName(integratorName(kind)), kind);
  }
  EXPECT_FALSE(integratorFromName("Implicit-Euler").has_value());
}

}  // namespace
}  // namespace weft
