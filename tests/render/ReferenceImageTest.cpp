// Golden-image test: a small fixed scene compared with tests/data/render/reference_scene.png.
//
// The comparison bounds how far any pixel may differ (the largest difference over its channels)
// and reports how many differ. To regenerate after an intended change:
// WEFT_UPDATE_REFERENCE_IMAGES=1 build/tests/weft_render_tests --gtest_filter='*Reference*',
// then look at the new picture before committing it. A Mesa or LLVM update that moves pixels
// needs the same deliberate new reference.
#include "RenderTestSupport.h"

#include <weft/render/Png.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

namespace weft::test {
namespace {

// Exact: llvmpipe draws it to identical bytes every run, on 0-8 threads and SSE2 to AVX-512 paths.
constexpr int kMaxChannelDifference = 0;  // 0–255 steps, on any pixel

const std::string kReferencePath = std::string(WEFT_TEST_DATA_DIR) + "/render/reference_scene.png";

// A folded cloth (no wireframe: at this size its lines would cover the cloth) over a floor with a sphere, a capsule and a box, seen from above and to the side.
RenderSettings referenceSettings() {
  RenderSettings s;
  s.width = 64;
  s.height = 48;
  s.camera.eye = Vec3(1.8, 2.0, 3.2);
  s.camera.target = Vec3(0.0, 1.0, 0.0);
  s.camera.verticalFovDegrees = 50.0;
  return s;
}

TEST_F(RenderTest, ReferenceSceneMatchesStoredImage) {
  const GridCloth curtain = makeDrapedCurtain(31, 11);
  const ClothRenderView views[] = {curtain.view()};
  const ColliderPrimitive colliders[] = {
      PlanePrimitive{.point = Vec3(0, 0, 0), .halfSize = 2.0},
      SpherePrimitive{.center = Vec3(0.5, 0.4, 0.6), .radius = 0.35, .color = {0.85f, 0.25f, 0.2f}},
      CapsulePrimitive{.a = Vec3(-0.9, 0.15, 1.0), .b = Vec3(-0.1, 0.15, 1.3), .radius = 0.15},
      BoxPrimitive{.center = Vec3(-1.1, 0.25, 0.2), .halfExtents = Vec3(0.25, 0.25, 0.25),
                   .rotation = Eigen::AngleAxisd(0.5, Vec3::UnitY()).toRotationMatrix(),
                   .color = {0.3f, 0.7f, 0.35f}}};
  auto renderer = ClothRenderer::create(*context, referenceSettings());
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  Image image;
  ASSERT_TRUE(renderer->renderFrame({views, colliders}, image).ok());

  const char* update = std::getenv("WEFT_UPDATE_REFERENCE_IMAGES");
  if (update != nullptr && std::string(update) == "1") {
    ASSERT_TRUE(writePng(kReferencePath, image).ok());
    // A 10× larger preview of the same scene, for the person checking the new reference.
    RenderSettings large = referenceSettings();
    large.width *= 10;
    large.height *= 10;
    ASSERT_TRUE(renderer->setSettings(large).ok());
    Image preview;
    ASSERT_TRUE(renderer->renderFrame({views, colliders}, preview).ok());
    ASSERT_TRUE(writePng((outputDir() / "reference_scene_preview.png").string(), preview).ok());
    GTEST_SKIP() << "wrote " << kReferencePath << "; look at it, then commit it";
  }

  Result<Image> reference = readPng(kReferencePath);
  ASSERT_TRUE(reference.ok()) << reference.error().message;
  ASSERT_EQ(reference->width, image.width);
  ASSERT_EQ(reference->height, image.height);
  // Per pixel, the largest difference over its four channels.
  int differing = 0, worst = 0;
  for (std::size_t i = 0; i < image.rgba.size(); i += 4) {
    int difference = 0;
    for (int c = 0; c < 4; ++c) difference = std::max(difference, std::abs(image.rgba[i + c] - reference->rgba[i + c]));
    worst = std::max(worst, difference);
    differing += difference > kMaxChannelDifference ? 1 : 0;
  }
  if (differing > 0) {
    const std::string actual = (outputDir() / "reference_scene_actual.png").string();
    (void)writePng(actual, image);
    std::printf("[ picture  ] %s (differs from the reference)\n", actual.c_str());
  }
  EXPECT_LE(worst, kMaxChannelDifference)
      << differing << " of " << image.width * image.height << " pixels differ by more than "
      << kMaxChannelDifference << " steps, the largest by " << worst;
  // The scene is not blank: cloth, colliders and floor cover most of the picture.
  EXPECT_GT(coverage(image, renderer->settings().background), 0.3);
}

}  // namespace
}  // namespace weft::test
