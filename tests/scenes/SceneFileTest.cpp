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

TEST(SceneFile, FaceContactsCanBeTurnedOffPerCloth) {
  Result<SceneDescription> scene =
      loadSceneText(R"({"version": 1, "cloths": [{"grid": {}, "faceContacts": false}]})");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_FALSE(scene->cloths[0].settings.faceContacts);
  Result<SceneDescription> wrong =
      loadSceneText(R"({"version": 1, "cloths": [{"grid": {}, "faceContacts": "no"}]})");
  ASSERT_FALSE(wrong.ok());
  EXPECT_THAT(wrong.error().message, HasSubstr("/cloths/0/faceContacts"));
  Result<SceneDescription> plain = loadSceneText(R"({"version": 1, "cloths": [{"grid": {}}]})");
  ASSERT_TRUE(plain.ok());
  EXPECT_TRUE(plain->cloths[0].settings.faceContacts);
}

TEST(SceneFile, KeysOfRemovedSettingsSayWhatReplacedThem) {
  // The rival contact pipeline's switch is gone: a file that still sets it is refused with a
  // message that says why and what to do.
  Result<SceneDescription> joint = loadSceneText(
      R"({"version": 1, "cloths": [{"grid": {}, "jointContactProjection": true}]})");
  ASSERT_FALSE(joint.ok());
  EXPECT_THAT(joint.error().message, HasSubstr("/cloths/0/jointContactProjection"));
  EXPECT_THAT(joint.error().message, HasSubstr("no longer exists"));
}

TEST(SceneFile, SelfContactsInTheSolveAreReadAndRangeChecked) {
  Result<SceneDescription> on = loadSceneText(
      R"({"version": 1, "cloths": [{"grid": {}, "solver": {"selfContactStiffness": 0.5}}]})");
  ASSERT_TRUE(on.ok()) << on.error().message;
  EXPECT_EQ(on->cloths[0].settings.solver.selfContactStiffness, 0.5);
  Result<SceneDescription> negative = loadSceneText(
      R"({"version": 1, "cloths": [{"grid": {}, "solver": {"selfContactStiffness": -1}}]})");
  ASSERT_FALSE(negative.ok());
  EXPECT_THAT(negative.error().message, HasSubstr("/cloths/0/solver/selfContactStiffness"));
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
        BadScene{"EscapedKey", R"({"version": 1, "a/b~c": 1, "cloths": [{"grid": {}}]})", "/a~1b~0c", "unknown key"},
        // Extremes (issue 22): numbers beyond a double, and values the engine would refuse.
        BadScene{"NumberBeyondADouble", CLOTH(R"(, "material": {"warpStretchStiffness": 1e400})"),
                 "/cloths/0/material/warpStretchStiffness", "is 1e400, beyond the largest double"},
        BadScene{"NegativeNumberBeyondADouble", R"({"version": 1, "world": {"gravity": [0, -1e400, 0]}, "cloths": [{"grid": {}}]})",
                 "/world/gravity/1", "is -1e400, beyond the largest double (about 1.8e308); give a finite number"},
        BadScene{"HugeStiffness", CLOTH(R"(, "material": {"bendingStiffness": 1e300})"),
                 "/cloths/0/material/bendingStiffness", "above 1e+30 (kMaxMaterialValue"},
        BadScene{"HugeSpring", CLOTH(R"(, "springs": {"shearStiffness": 1e31})"),
                 "/cloths/0/springs/shearStiffness", "kMaxMaterialValue"},
        BadScene{"HugeGravity", R"({"version": 1, "world": {"gravity": [0, -1e30, 0]}, "cloths": [{"grid": {}}]})",
                 "/world/gravity", "above 10000 m/s² (kMaxGravity"},
        BadScene{"HugeWind", R"({"version": 1, "world": {"wind": [3e4, 0, 0]}, "cloths": [{"grid": {}}]})",
                 "/world/wind", "faster than 10000 m/s (kMaxSpeed)"},
        BadScene{"HugeWindKeyframe", R"({"version": 1, "world": {"windScript": {"keyframes": [{"time": 0}, {"time": 1, "wind": [0, 0, 1e5]}]}}, "cloths": [{"grid": {}}]})",
                 "/world/windScript/keyframes/1/wind", "kMaxSpeed"},
        BadScene{"FastCollider", R"({"version": 1, "cloths": [{"grid": {}}], "colliders": [{"type": "sphere", "radius": 1, "linearVelocity": [0, 0, -1e30]}]})",
                 "/colliders/0/linearVelocity", "kMaxSpeed"},
        BadScene{"FarTranslation", CLOTH(R"(, "translation": [1e30, 0, 0])"),
                 "/cloths/0/translation", "beyond the 1e+06 m a coordinate may have (kMaxCoordinate)"},
        BadScene{"FarGrid", R"({"version": 1, "cloths": [{"grid": {"origin": [0, 0, 2e6]}}]})",
                 "/cloths/0/grid", "kMaxCoordinate"},
        BadScene{"HugePleats", CLOTH(R"(, "initialPleats": {"amplitude": 1e300})"),
                 "/cloths/0/initialPleats", "kMaxCoordinate"},
        BadScene{"GridBeyondTheLimit", R"({"version": 1, "cloths": [{"grid": {"columns": 100000, "rows": 100000}}]})",
                 "/cloths/0/grid", "more than the limit of 4000000 per cloth; use fewer columns and rows"},
        BadScene{"BadWeldTolerance", R"({"version": 1, "cloths": [{"mesh": {"obj": "weft_no_such_file.obj", "weldTolerance": 2}}]})",
                 "/cloths/0/mesh/weldTolerance", "below 1"}),
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

TEST(SceneFile, DevicesAndOversizedFilesAreRefusedUnread) {
  // `weft validate /dev/zero` once ended in std::bad_alloc, reading forever.
  for (const char* device : {"/dev/zero", "/dev/urandom"}) {
    SceneParseOutcome outcome = parseSceneFile(device);
    ASSERT_EQ(outcome.issues.size(), 1u) << device;
    EXPECT_THAT(outcome.issues[0].message,
                HasSubstr(std::string("scene file '") + device + "': it is a character device"));
  }
  // A mesh that is a device, named by its JSON path.
  SceneParseOutcome mesh = parseSceneText(R"({"version": 1, "cloths": [{"mesh": {"obj": "/dev/zero"}}]})");
  ASSERT_EQ(mesh.issues.size(), 1u);
  EXPECT_EQ(mesh.issues[0].path, "/cloths/0/mesh/obj");
  EXPECT_THAT(mesh.issues[0].message, HasSubstr("OBJ file '/dev/zero': it is a character device"));
  // Above SceneLoadOptions::maxFileBytes: refused by its size.
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "weft_big_scene.json";
  std::ofstream(path) << R"({"version": 1, "cloths": [{"grid": {}}]})";
  SceneLoadOptions options;
  options.maxFileBytes = 16;
  SceneParseOutcome big = parseSceneFile(path.string(), options);
  ASSERT_EQ(big.issues.size(), 1u);
  EXPECT_THAT(big.issues[0].message, HasSubstr("bytes, more than the limit of 16 bytes"));
  EXPECT_TRUE(parseSceneFile(path.string()).scene.has_value());
  std::filesystem::remove(path);
}

TEST(SceneFile, GridsBeyondTheMemoryAreRefusedBeforeTheyAreBuilt) {
  // Within a raised vertex limit, but not within any machine's memory: refused by the estimate.
  SceneLoadOptions options;
  options.maxVerticesPerCloth = 4'000'000'000u;
  SceneParseOutcome outcome = parseSceneText(
      R"({"version": 1, "cloths": [{"grid": {"columns": 50000, "rows": 40000}}]})", options);
  ASSERT_EQ(outcome.issues.size(), 1u) << formatIssues(outcome.issues);
  EXPECT_EQ(outcome.issues[0].path, "/cloths/0/grid");
  EXPECT_THAT(outcome.issues[0].message,
              HasSubstr("a cloth of 2000000000 vertices (50000 x 40000 grid) needs about"));
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("are available; use fewer columns and rows"));
}

TEST(SceneFile, MeshClothsAreWeldedAndTheirPinsCountTheFilesVertices) {
  const std::filesystem::path folder = std::filesystem::temp_directory_path() / "weft_scene_seam";
  std::filesystem::create_directories(folder);
  // Two quads written as two texture islands: vertices 1 and 4 (0-based) are the same point, and
  // so are 3 and 6.
  std::ofstream(folder / "seam.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                        "v 1 0 0\nv 2 0 0\nv 1 1 0\nv 2 1 0\n"
                                        "f 1 2 4 3\nf 5 6 8 7\n";
  auto load = [&](const std::string& mesh, const std::string& pins) {
    std::ofstream(folder / "scene.json")
        << R"({"version": 1, "cloths": [{"mesh": {"obj": "seam.obj")" + mesh + R"(}, "pins": )" + pins + "}]}";
    return loadSceneFile((folder / "scene.json").string());
  };
  Result<SceneDescription> scene = load("", R"([{"vertices": [2, 6]}])");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  const ClothModel& model = *scene->cloths[0].model;
  EXPECT_EQ(model.vertexCount(), 6u);
  EXPECT_EQ(model.meshImport().weldedVertices, 2u);
  // The file's vertex 6 is the model's vertex 3 (the copy of 3 is welded into it).
  EXPECT_EQ(scene->cloths[0].settings.pinnedVertices, (std::vector<Index>{2, 3}));
  // Pinning both copies of one point pins one vertex twice.
  scene = load("", R"([{"vertices": [3]}, {"vertices": [6]}])");
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.error().message, HasSubstr("/cloths/0/pins/1: vertex 6 is already pinned by /cloths/0/pins/0 "
                                               "(coincident vertices are welded into one)"));
  // Welding off: eight vertices, and the file's numbers are the model's.
  scene = load(R"(, "weldVertices": false)", R"([{"vertices": [3, 6]}])");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_EQ(scene->cloths[0].model->vertexCount(), 8u);
  EXPECT_EQ(scene->cloths[0].settings.pinnedVertices, (std::vector<Index>{3, 6}));
  // A wider tolerance and the winding switch are read.
  scene = load(R"(, "weldTolerance": 1e-4, "fixWinding": false)", "[]");
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  std::filesystem::remove_all(folder);
}

TEST(SceneFile, AMoebiusStripIsRefusedNamingItsTriangles) {
  const std::string path =
      (std::filesystem::path(WEFT_TEST_DATA_DIR).parent_path() / "scenes/data/moebius.json").string();
  SceneParseOutcome outcome = parseSceneFile(path);
  ASSERT_EQ(outcome.issues.size(), 1u) << formatIssues(outcome.issues);
  EXPECT_EQ(outcome.issues[0].path, "/cloths/0/mesh/obj");
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("moebius.obj"));
  EXPECT_THAT(outcome.issues[0].message, ::testing::ContainsRegex(
      "triangles [0-9]+ and [0-9]+ across edge \\([0-9]+, [0-9]+\\) cannot be wound consistently"));
  EXPECT_THAT(outcome.issues[0].message, HasSubstr("non-orientable (a Möbius strip)"));
}

TEST(SceneFile, ThreadCountsOutOfRangeAreRefusedWhenTheSceneIsBuilt) {
  for (int threads : {-1, 100000}) {
    Result<SceneDescription> description = loadSceneText(R"({"version": 1, "cloths": [{"grid": {"columns": 3, "rows": 3}}]})");
    ASSERT_TRUE(description.ok());
    ScriptedSceneSettings settings;
    settings.threadCount = threads;
    Result<ScriptedScene> scene = ScriptedScene::create(std::move(description).value(), settings);
    ASSERT_FALSE(scene.ok()) << threads;
    EXPECT_THAT(scene.error().message,
                HasSubstr("WorldSettings::threadCount = " + std::to_string(threads) + " is out of range"));
  }
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
