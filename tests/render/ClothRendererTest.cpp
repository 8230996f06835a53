#include "RenderTestSupport.h"

#include <weft/render/ClothRenderer.h>
#include <weft/render/Png.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace weft::test {
namespace {

constexpr double kSide = 1.5;      // m, the flat square's side
constexpr double kDistance = 3.0;  // m, camera to square
constexpr double kFov = 50.0;      // degrees, vertical

// Camera on +z looking at the square's centre; background and colours far apart.
RenderSettings squareSettings(int width = 320, int height = 240) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  s.camera.eye = Vec3(0, 0, kDistance);
  s.camera.target = Vec3(0, 0, 0);
  s.camera.verticalFovDegrees = kFov;
  s.background = {0.1f, 0.1f, 0.1f};
  s.drawColliders = true;
  return s;
}

// Expected share of the image covered by a square of side kSide parallel to the image plane:
// its half-height in normalised device coordinates is (side / 2) / (distance · tan(fov / 2)); the
// half-width is that over the aspect ratio; the image spans 2 × 2 in those units.
double expectedSquareCoverage(int width, int height) {
  const double ndcHalfHeight = (kSide / 2) / (kDistance * std::tan(kFov * std::numbers::pi / 360.0));
  const double ndcHalfWidth = ndcHalfHeight * height / width;
  return ndcHalfHeight * ndcHalfWidth;
}

TEST_F(RenderTest, ImageHasTheRequestedSize) {
  auto renderer = ClothRenderer::create(*context, squareSettings(200, 150));
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const GridCloth square = makeFlatSquare(kSide);
  const ClothRenderView views[] = {square.view()};
  Image image;
  ASSERT_TRUE(renderer->renderFrame({views, {}}, image).ok());
  EXPECT_EQ(image.width, 200);
  EXPECT_EQ(image.height, 150);
  EXPECT_EQ(image.rgba.size(), 200u * 150u * 4u);

  // A new resolution in the settings resizes the framebuffer.
  RenderSettings wide = renderer->settings();
  wide.width = 96;
  wide.height = 40;
  ASSERT_TRUE(renderer->setSettings(wide).ok());
  ASSERT_TRUE(renderer->renderFrame({views, {}}, image).ok());
  EXPECT_EQ(image.width, 96);
  EXPECT_EQ(image.height, 40);
  EXPECT_EQ(context->width(), 96);
}

TEST_F(RenderTest, FlatSquareCoversItsProjectedArea) {
  for (auto [width, height] : {std::pair{320, 240}, std::pair{400, 200}}) {
    const RenderSettings settings = squareSettings(width, height);
    auto renderer = ClothRenderer::create(*context, settings);
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    const GridCloth square = makeFlatSquare(kSide);
    const ClothRenderView views[] = {square.view()};
    Image image;
    ASSERT_TRUE(renderer->renderFrame({views, {}}, image).ok());
    const double expected = expectedSquareCoverage(width, height);
    const double measured = coverage(image, settings.background);
    EXPECT_NEAR(measured / expected, 1.0, 0.03) << width << "x" << height << ": measured " << measured
                                               << ", expected " << expected;
  }
}

TEST_F(RenderTest, CornersAreBackground) {
  const RenderSettings settings = squareSettings();
  auto renderer = ClothRenderer::create(*context, settings);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const GridCloth square = makeFlatSquare(kSide);
  const ClothRenderView views[] = {square.view()};
  Image image;
  ASSERT_TRUE(renderer->renderFrame({views, {}}, image).ok());
  for (auto [x, y] : {std::pair{0, 0}, std::pair{image.width - 1, 0}, std::pair{0, image.height - 1},
                      std::pair{image.width - 1, image.height - 1}}) {
    EXPECT_TRUE(matches(image.pixel(x, y), settings.background)) << "corner " << x << "," << y;
  }
  // The centre is cloth, and rows are top-down: alpha is opaque everywhere.
  EXPECT_FALSE(matches(image.pixel(image.width / 2, image.height / 2), settings.background));
  EXPECT_EQ(image.pixel(0, 0)[3], 255);
}

TEST_F(RenderTest, FrontAndBackFacesShadeDifferently) {
  RenderSettings settings = squareSettings();
  auto renderer = ClothRenderer::create(*context, settings);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const GridCloth square = makeFlatSquare(kSide);
  const ClothRenderView views[] = {square.view()};

  Image front, back;
  ASSERT_TRUE(renderer->renderFrame({views, {}}, front).ok());
  settings.camera.eye = Vec3(0, 0, -kDistance);  // look at the other side
  ASSERT_TRUE(renderer->setSettings(settings).ok());
  ASSERT_TRUE(renderer->renderFrame({views, {}}, back).ok());

  // The light follows the camera: both sides get the same Lambert factor, only the tint differs.
  const Vec3 light = settings.lightDirection.normalized();
  const double shade = settings.ambient + (1.0 - settings.ambient) * light.z();
  const auto shaded = [&](const ColorRgb& c) {
    return ColorRgb{float(c.r * shade), float(c.g * shade), float(c.b * shade)};
  };
  const Rgba8 frontPixel = front.pixel(front.width / 2, front.height / 2);
  const Rgba8 backPixel = back.pixel(back.width / 2, back.height / 2);
  EXPECT_TRUE(matches(frontPixel, shaded(settings.clothFront), 2))
      << int(frontPixel[0]) << " " << int(frontPixel[1]) << " " << int(frontPixel[2]);
  EXPECT_TRUE(matches(backPixel, shaded(settings.clothBack), 2))
      << int(backPixel[0]) << " " << int(backPixel[1]) << " " << int(backPixel[2]);
  EXPECT_NE(frontPixel, backPixel);
}

TEST_F(RenderTest, GivenNormalsAndComputedNormalsAgreeOnAFlatSquare) {
  auto renderer = ClothRenderer::create(*context, squareSettings());
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  GridCloth computed = makeFlatSquare(kSide);
  GridCloth given = computed;
  given.normals.assign(given.positions.size(), Vec3::UnitZ());
  const ClothRenderView computedViews[] = {computed.view()};
  const ClothRenderView givenViews[] = {given.view()};
  Image a, b;
  ASSERT_TRUE(renderer->renderFrame({computedViews, {}}, a).ok());
  ASSERT_TRUE(renderer->renderFrame({givenViews, {}}, b).ok());
  EXPECT_EQ(a, b);
}

TEST_F(RenderTest, SameFrameTwiceIsBitIdentical) {
  RenderSettings settings = squareSettings();
  settings.wireframe = true;
  settings.camera.eye = Vec3(1.6, 1.4, 2.6);
  settings.camera.target = Vec3(0, 1.2, 0);
  auto renderer = ClothRenderer::create(*context, settings);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const GridCloth curtain = makeDrapedCurtain();
  const ClothRenderView views[] = {curtain.view()};
  const ColliderPrimitive colliders[] = {SpherePrimitive{.center = Vec3(0.3, 1.1, 0.3), .radius = 0.25},
                                         PlanePrimitive{}};
  Image first, second;
  ASSERT_TRUE(renderer->renderFrame({views, colliders}, first).ok());
  ASSERT_TRUE(renderer->renderFrame({views, colliders}, second).ok());
  EXPECT_GT(coverage(first, settings.background), 0.05);
  EXPECT_EQ(first, second);
  EXPECT_TRUE(writePng((outputDir() / "curtain_wireframe.png").string(), first).ok());
}

TEST_F(RenderTest, WireframeDrawsEdgesInItsColour) {
  RenderSettings settings = squareSettings();
  settings.wireframeColor = {1.0f, 0.0f, 1.0f};
  auto renderer = ClothRenderer::create(*context, settings);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const GridCloth square = makeFlatSquare(kSide);
  const ClothRenderView views[] = {square.view()};
  Image plain, wired;
  ASSERT_TRUE(renderer->renderFrame({views, {}}, plain).ok());
  settings.wireframe = true;
  ASSERT_TRUE(renderer->setSettings(settings).ok());
  ASSERT_TRUE(renderer->renderFrame({views, {}}, wired).ok());
  const auto countWire = [&](const Image& image) {
    int n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) n += matches(image.pixel(x, y), settings.wireframeColor, 0) ? 1 : 0;
    return n;
  };
  EXPECT_EQ(countWire(plain), 0);
  // 11 × 11 vertices: 10 cells a side of ~12 px, each line ~120 px long; at least half must show.
  EXPECT_GT(countWire(wired), 10 * 120);
}

TEST_F(RenderTest, CollidersAreDrawnInTheirOwnColour) {
  RenderSettings settings = squareSettings();
  auto renderer = ClothRenderer::create(*context, settings);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  const ColorRgb red{1.0f, 0.0f, 0.0f}, green{0.0f, 1.0f, 0.0f};
  // A sphere on the left, a box on the right, nothing in the middle column.
  const ColliderPrimitive colliders[] = {
      SpherePrimitive{.center = Vec3(-0.8, 0, 0), .radius = 0.3, .color = red},
      BoxPrimitive{.center = Vec3(0.8, 0, 0), .halfExtents = Vec3(0.25, 0.25, 0.25), .color = green},
      CapsulePrimitive{.a = Vec3(-0.5, 0.8, 0), .b = Vec3(0.5, 0.8, 0), .radius = 0.1}};
  Image image;
  ASSERT_TRUE(renderer->renderFrame({{}, colliders}, image).ok());
  const auto [sphereX, sphereY] = projectToPixel(settings, Vec3(-0.8, 0, 0));
  const Rgba8 sphere = image.pixel(sphereX, sphereY);
  const Rgba8 middle = image.pixel(image.width / 2, image.height / 2);
  EXPECT_GT(sphere[0], 150);
  EXPECT_EQ(sphere[1], 0);
  EXPECT_TRUE(matches(middle, settings.background));

  int greenPixels = 0, greyPixels = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Rgba8 p = image.pixel(x, y);
      greenPixels += (p[1] > 100 && p[0] == 0 && p[2] == 0) ? 1 : 0;
      greyPixels += (p[0] > 100 && std::abs(p[0] - p[1]) <= 3 && std::abs(p[1] - p[2]) <= 3) ? 1 : 0;
    }
  }
  EXPECT_GT(greenPixels, 200);  // the box: ~0.5 m wide at 3 m is ~40 px square
  EXPECT_GT(greyPixels, 200);   // the capsule in the default collider grey

  // Colliders can be switched off.
  settings.drawColliders = false;
  ASSERT_TRUE(renderer->setSettings(settings).ok());
  ASSERT_TRUE(renderer->renderFrame({{}, colliders}, image).ok());
  EXPECT_EQ(coverage(image, settings.background), 0.0);
}

TEST_F(RenderTest, BadInputIsReportedNotDrawn) {
  auto renderer = ClothRenderer::create(*context, squareSettings());
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  GridCloth square = makeFlatSquare(kSide, 3);
  square.indices[4] = 9;  // one past the last vertex
  const ClothRenderView views[] = {square.view()};
  auto frame = renderer->renderFrame({views, {}});
  ASSERT_FALSE(frame.ok());
  EXPECT_NE(frame.error().message.find("cloth 0"), std::string::npos) << frame.error().message;
  EXPECT_NE(frame.error().message.find("vertex 9"), std::string::npos) << frame.error().message;

  GridCloth ragged = makeFlatSquare(kSide, 3);
  ragged.normals.assign(5, Vec3::UnitZ());
  const ClothRenderView raggedViews[] = {ragged.view()};
  frame = renderer->renderFrame({raggedViews, {}});
  ASSERT_FALSE(frame.ok());
  EXPECT_NE(frame.error().message.find("normals"), std::string::npos) << frame.error().message;

  RenderSettings bad = squareSettings();
  bad.camera.verticalFovDegrees = 0;
  const Status status = renderer->setSettings(bad);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("verticalFovDegrees"), std::string::npos) << status.error().message;
  EXPECT_EQ(renderer->settings().camera.verticalFovDegrees, kFov);  // unchanged
}

// The 41 × 31 benchmark curtain (2,400 triangles) in drape-like folds at the two resolutions
// the benchmark uses. Writes PNGs for people to look at and prints the measured times; asserts
// only what the picture must show, never how long it took.
TEST_F(RenderTest, DrapedCurtainShowsBothSides) {
  const GridCloth curtain = makeDrapedCurtain();
  ASSERT_EQ(curtain.indices.size(), 2400u * 3u);
  const ClothRenderView views[] = {curtain.view()};
  const ColliderPrimitive colliders[] = {SpherePrimitive{.center = Vec3(0.3, 1.1, 0.35), .radius = 0.25},
                                         PlanePrimitive{.point = Vec3(0, 0, 0), .halfSize = 2.5}};
  for (auto [width, height] : {std::pair{1280, 720}, std::pair{640, 360}}) {
    // Timed frames: the cloth alone (the benchmark's 2,400 triangles) from the default camera,
    // which faces the curtain as the curtain runner does.
    RenderSettings front;
    front.width = width;
    front.height = height;
    auto renderer = ClothRenderer::create(*context, front);
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    Image image;
    constexpr int kWarmUp = 3, kFrames = 30;
    std::vector<double> renderMs, readbackMs;
    for (int frame = 0; frame < kWarmUp + kFrames; ++frame) {
      auto timing = renderer->renderFrame({views, {}}, image);
      ASSERT_TRUE(timing.ok()) << timing.error().message;
      if (frame >= kWarmUp) {
        renderMs.push_back(timing->renderMs);
        readbackMs.push_back(timing->readbackMs);
      }
    }
    std::sort(renderMs.begin(), renderMs.end());
    std::sort(readbackMs.begin(), readbackMs.end());
    const char* threads = std::getenv("LP_NUM_THREADS");
    std::printf("[ timing   ] %dx%d, 2400 triangles covering %.0f%% of the pixels, %s: render %.2f ms (min %.2f), "
                "readback %.2f ms (min %.2f); median of %d frames, LP_NUM_THREADS=%s\n",
                width, height, 100.0 * coverage(image, front.background), context->renderer().c_str(),
                renderMs[kFrames / 2], renderMs.front(), readbackMs[kFrames / 2], readbackMs.front(), kFrames,
                threads ? threads : "unset");
    RecordProperty("render_ms_" + std::to_string(width), std::to_string(renderMs[kFrames / 2]));
    EXPECT_GT(coverage(image, front.background), 0.2);  // the default camera frames the curtain
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    ASSERT_TRUE(writePng((outputDir() / ("curtain_front_" + size + ".png")).string(), image).ok());

    // The picture: level with the cloth and past its end, so the far flanks of the folds show
    // their back; with a sphere and the floor.
    RenderSettings side = front;
    side.camera.eye = Vec3(2.3, 1.4, 1.3);
    side.camera.target = Vec3(0.1, 1.2, 0);
    side.camera.verticalFovDegrees = 55;
    ASSERT_TRUE(renderer->setSettings(side).ok());
    ASSERT_TRUE(renderer->renderFrame({views, colliders}, image).ok());

    // Folds turn both sides towards the camera: both tints must be on screen.
    int frontish = 0, backish = 0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const Rgba8 p = image.pixel(x, y);
        frontish += (p[2] > p[0] + 40) ? 1 : 0;  // blue front
        backish += (p[0] > p[2] + 40) ? 1 : 0;   // orange back
      }
    }
    EXPECT_GT(frontish, image.width * image.height / 20);
    EXPECT_GT(backish, image.width * image.height / 200);
    const std::filesystem::path png = outputDir() / ("curtain_side_" + size + ".png");
    ASSERT_TRUE(writePng(png.string(), image).ok());
    std::printf("[ picture  ] %s\n", png.c_str());
  }
}

}  // namespace
}  // namespace weft::test
