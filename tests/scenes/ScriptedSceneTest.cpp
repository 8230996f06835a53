// ScriptedScene: curtain.json reproduces weft::CurtainScene; keyframed pins and colliders follow
// their tracks; constant collider velocities are kept.
#include <weft/scenes/Curtain.h>
#include <weft/scenes/SceneFile.h>
#include <weft/scenes/ScriptedScene.h>

#include <gtest/gtest.h>

#include <cmath>

namespace weft {
namespace {

const std::string kSceneDir = WEFT_SCENE_DATA_DIR;

ScriptedScene build(const std::string& json, int threads = 1) {
  Result<SceneDescription> description = loadSceneText(json);
  EXPECT_TRUE(description.ok()) << description.error().message;
  ScriptedSceneSettings settings;
  settings.threadCount = threads;
  Result<ScriptedScene> scene = ScriptedScene::create(std::move(description).value(), settings);
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  return std::move(scene).value();
}

ScriptedScene curtainFromFile() {
  Result<SceneDescription> description = loadSceneFile(kSceneDir + "/curtain.json");
  EXPECT_TRUE(description.ok()) << description.error().message;
  ScriptedSceneSettings settings;
  settings.threadCount = 2;
  Result<ScriptedScene> scene = ScriptedScene::create(std::move(description).value(), settings);
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  return std::move(scene).value();
}

// curtain.json and CurtainScene compute their scripts with different expressions in two places:
// the sphere's withdrawal (CurtainScene: −0.5 + 0.8·(1 − s); keyframes: 0.3 + (−0.5 − 0.3)·s) and
// the rod from 6 s on (CurtainScene: 1 − 0.7·g with g = 1 or 1 − s; keyframes: 0.3 held, then
// 0.3 + 0.7·s; and 1 − (1 − 0.3) is 0.30000000000000004, not 0.3). Elsewhere the arithmetic is the
// same operation for operation, so the two runs are bitwise equal until the sphere starts to
// withdraw (t = 2 s, frame 120); after that the scripts differ by an ulp and the fold dynamics
// amplify it. So: the same bits for the first 120 frames, and both scripts within 1e-12 m of each
// other at every frame of the 10 s.
TEST(ScriptedScene, CurtainFileIsBitwiseTheCurtainSceneUntilTheSphereWithdraws) {
  ScriptedScene fromFile = curtainFromFile();
  CurtainSettings settings;
  settings.threadCount = 2;
  Result<CurtainScene> reference = CurtainScene::create(settings);
  ASSERT_TRUE(reference.ok()) << reference.error().message;
  ASSERT_EQ(fromFile.world().stateHash(), reference->world().stateHash()) << "initial pleats differ";
  for (Index frame = 1; frame <= 120; ++frame) {
    const StepStatus a = fromFile.stepFrame();
    const StepStatus b = reference->stepFrame();
    ASSERT_EQ(a, b) << "frame " << frame;
    ASSERT_EQ(fromFile.world().stateHash(), reference->world().stateHash()) << "frame " << frame;
  }
  // The sphere really pushed into the curtain in that time (the comparison covers contact).
  EXPECT_GT(fromFile.world().stats().contacts, 0u);
}

TEST(ScriptedScene, CurtainFileScriptsMatchTheCurtainSceneForTheWholeRun) {
  ScriptedScene fromFile = curtainFromFile();
  const SceneDescription& description = fromFile.description();
  ASSERT_EQ(description.frames, CurtainScene::kFrames);
  ASSERT_EQ(description.frameDt, CurtainScene::kFrameDt);
  const ClothModel& model = *description.cloths[0].model;
  const std::vector<Index>& pins = description.cloths[0].settings.pinnedVertices;
  ASSERT_EQ(pins.size(), 41u);
  std::vector<Vec3> targets;
  Real largestPinGap = 0, largestSphereGap = 0;
  for (Index frame = 0; frame <= CurtainScene::kFrames; ++frame) {
    const Real t = frame * CurtainScene::kFrameDt;
    fromFile.pinTargetsAt(0, t, targets);
    for (std::size_t k = 0; k < pins.size(); ++k) {
      const Vec3 expected = CurtainScene::pinTarget(model.restPositions()[pins[k]], t);
      largestPinGap = std::max(largestPinGap, (targets[k] - expected).norm());
      if (t <= 6) {
        ASSERT_EQ(targets[k], expected) << "frame " << frame << ", pin " << k;
      }
    }
    const Vec3 sphere = keyframePose(description.colliders[0], t).position;
    largestSphereGap = std::max(largestSphereGap, (sphere - CurtainScene::spherePosition(t)).norm());
    if (t <= 2) {
      ASSERT_EQ(sphere, CurtainScene::spherePosition(t)) << "frame " << frame;
    }
  }
  EXPECT_LT(largestPinGap, 1e-12);
  EXPECT_LT(largestSphereGap, 1e-12);
  // And the rod does gather: at 7 s the right end is at 30 % of the width.
  fromFile.pinTargetsAt(0, 7.0, targets);
  EXPECT_NEAR(targets.back().x(), -1 + 2 * CurtainScene::kGatheredFraction, 1e-12);
}

TEST(ScriptedScene, KeyframedColliderFollowsItsTrack) {
  ScriptedScene scene = build(R"({"version": 1, "run": {"framesPerSecond": 60},
      "cloths": [{"grid": {"columns": 3, "rows": 3, "origin": [0, 5, 0]}, "selfCollision": false}],
      "colliders": [{"type": "box", "halfExtents": [0.1, 0.1, 0.1], "motion": {"keyframes": [
          {"time": 0, "position": [0, 0, 0]},
          {"time": 1, "position": [1, 0, 0], "rotation": {"axis": [0, 1, 0], "angleDegrees": 90}}]}}]})");
  for (int frame = 0; frame < 30; ++frame) scene.stepFrame();
  // Half way: linear easing puts it at x = 0.5, turned 45° about y.
  const RigidMotion& half = motion(*scene.world().collider(scene.collider(0)).value());
  EXPECT_NEAR(half.pose.position.x(), 0.5, 1e-9);
  EXPECT_NEAR(half.pose.rotation.angularDistance(Quat(Eigen::AngleAxis<Real>(M_PI / 4, Vec3::UnitY()))), 0, 1e-9);
  EXPECT_NEAR(half.linearVelocity.x(), 1.0, 1e-9);  // 1 m in 1 s
  EXPECT_NEAR(half.angularVelocity.y(), M_PI / 2, 1e-6);
  for (int frame = 30; frame < 90; ++frame) scene.stepFrame();
  // After the last keyframe it stays put.
  const RigidMotion& end = motion(*scene.world().collider(scene.collider(0)).value());
  EXPECT_NEAR((end.pose.position - Vec3(1, 0, 0)).norm(), 0, 1e-9);
  EXPECT_NEAR(end.linearVelocity.norm(), 0, 1e-9);
  EXPECT_NEAR(end.angularVelocity.norm(), 0, 1e-6);
}

TEST(ScriptedScene, PinScriptsMoveTheirGroupAndOtherPinsHold) {
  // Two pinned corners of a hanging square: one carried 0.3 m along +x over 0.5 s, one still.
  ScriptedScene scene = build(R"({"version": 1,
      "cloths": [{"grid": {"columns": 5, "rows": 5, "width": 0.4, "height": 0.4, "origin": [0, 1, 0]},
                  "selfCollision": false,
                  "pins": [{"vertices": [24], "script": {"keyframes": [
                              {"time": 0, "translation": [0, 0, 0]},
                              {"time": 0.5, "translation": [0.3, 0, 0]}]}},
                           {"vertices": [20]}]}]})");
  const Vec3 movingStart = scene.world().positions(scene.cloth(0)).value()[24];
  const Vec3 stillStart = scene.world().positions(scene.cloth(0)).value()[20];
  const Vec3 freeStart = scene.world().positions(scene.cloth(0)).value()[0];
  for (int frame = 0; frame < 45; ++frame) ASSERT_EQ(scene.stepFrame(), StepStatus::Ok);
  const std::span<const Vec3> x = scene.world().positions(scene.cloth(0)).value();
  EXPECT_NEAR((x[24] - (movingStart + Vec3(0.3, 0, 0))).norm(), 0, 1e-12);
  EXPECT_EQ(x[20], stillStart);
  EXPECT_GT((x[0] - freeStart).norm(), 0.01);  // the free corner swings
}

TEST(ScriptedScene, PinsAttachedToAColliderRideOnIt) {
  // A square hanging from a rod (a capsule turned to lie along x) that slides 0.4 m along +x in
  // 1 s: the top row keeps its offsets in the rod's frame, so it moves exactly as far. (Turning
  // bodies are covered by the World API's own tests, AttachmentAndForcesTest.)
  ScriptedScene scene = build(R"({"version": 1,
      "cloths": [{"grid": {"columns": 5, "rows": 5, "width": 0.4, "height": 0.4, "origin": [-0.2, 0.6, 0]},
                  "selfCollision": false, "pins": [{"row": 4, "attachTo": "rod"}]}],
      "colliders": [{"type": "capsule", "name": "rod", "radius": 0.01, "halfLength": 0.3,
                     "motion": {"keyframes": [
                        {"time": 0, "position": [0, 1.02, 0], "rotation": {"axis": [0, 0, 1], "angleDegrees": 90}},
                        {"time": 1, "position": [0.4, 1.02, 0]}]}}]})");
  ASSERT_EQ(scene.world().attachedVertexCount(scene.cloth(0)).value(), 5u);
  const Vec3Array start(scene.world().positions(scene.cloth(0)).value().begin(),
                        scene.world().positions(scene.cloth(0)).value().end());
  for (int frame = 0; frame < 60; ++frame) ASSERT_EQ(scene.stepFrame(), StepStatus::Ok);
  const std::span<const Vec3> x = scene.world().positions(scene.cloth(0)).value();
  for (Index column = 0; column < 5; ++column) {
    const Index vertex = 20 + column;
    EXPECT_NEAR((x[vertex] - (start[vertex] + Vec3(0.4, 0, 0))).norm(), 0, 1e-9) << "vertex " << vertex;
  }
  EXPECT_LT(x[0].y(), start[0].y());  // the free bottom row hangs on
}

TEST(ScriptedScene, WindFollowsItsKeyframes) {
  const char* json = R"({"version": 1, "world": {"wind": [0, 0, 9], "windScript": {"keyframes": [
          {"time": 0.5, "wind": [0, 0, 0]}, {"time": 1.5, "wind": [0, 0, 6]}]}},
      "cloths": [{"grid": {"columns": 5, "rows": 5, "width": 0.4, "height": 0.4, "origin": [-0.2, 0.6, 0]},
                  "selfCollision": false, "pins": [{"row": 4}]}]})";
  Result<SceneDescription> description = loadSceneText(json);
  ASSERT_TRUE(description.ok()) << description.error().message;
  // The first keyframe's wind is the start wind (it overrides "wind"), held until 0.5 s.
  EXPECT_EQ(description->wind, Vec3::Zero());
  EXPECT_EQ(windAt(description.value(), 0.25), Vec3::Zero());
  EXPECT_NEAR((windAt(description.value(), 1.0) - Vec3(0, 0, 3)).norm(), 0, 1e-12);
  EXPECT_EQ(windAt(description.value(), 2.0), Vec3(0, 0, 6));

  ScriptedScene scene = build(json);
  for (int frame = 0; frame < 30; ++frame) ASSERT_EQ(scene.stepFrame(), StepStatus::Ok);
  EXPECT_EQ(scene.world().wind(), Vec3::Zero());  // still calm at 0.5 s
  // No wind: the hanging square stays in its plane.
  EXPECT_NEAR(scene.world().positions(scene.cloth(0)).value()[0].z(), 0, 1e-9);
  for (int frame = 30; frame < 120; ++frame) ASSERT_EQ(scene.stepFrame(), StepStatus::Ok);
  EXPECT_EQ(scene.world().wind(), Vec3(0, 0, 6));
  EXPECT_GT(scene.world().positions(scene.cloth(0)).value()[0].z(), 0.02);  // blown downwind
}

TEST(ScriptedScene, ScaleAndRotationAreAboutTheAnchor) {
  PinScript script;
  script.anchor = Vec3(1, 0, 0);
  script.rotates = true;
  PinKeyframe start;
  PinKeyframe end;
  end.time = 2;
  end.scale = Vec3(2, 1, 1);
  end.rotation = Quat(Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitZ()));
  script.keyframes = {start, end};
  // (2, 0, 0) is 1 m from the anchor along x: scaled to 2 m, then turned to +y.
  EXPECT_NEAR((pinTarget(script, Vec3(2, 0, 0), 2.0) - Vec3(1, 2, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((pinTarget(script, Vec3(2, 0, 0), 5.0) - Vec3(1, 2, 0)).norm(), 0, 1e-12);  // held
  EXPECT_EQ(pinTarget(script, Vec3(2, 0, 0), 0.0), Vec3(2, 0, 0));
  EXPECT_EQ(ease(Easing::Smoothstep, 0.5), 0.5);
  EXPECT_EQ(ease(Easing::Smoothstep, 0.25), 0.25 * 0.25 * 2.5);
  EXPECT_EQ(ease(Easing::Linear, 1.5), 1.0);
}

TEST(ScriptedScene, ProjectileSceneDoesNotTunnel) {
  Result<SceneDescription> description = loadSceneFile(kSceneDir + "/projectile.json");
  ASSERT_TRUE(description.ok()) << description.error().message;
  Result<ScriptedScene> scene = ScriptedScene::create(std::move(description).value());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  for (int frame = 0; frame < 3; ++frame) scene->stepFrame();
  const Real sphereZ = motion(*scene->world().collider(scene->collider(0)).value()).pose.position.z();
  EXPECT_GT(sphereZ, 1.4);  // constant 50 m/s: 2.5 m in 3 frames, from z = −1
  EXPECT_GT(scene->world().positions(scene->cloth(0)).value()[10 * 21 + 10].z(), sphereZ);
}

}  // namespace
}  // namespace weft
