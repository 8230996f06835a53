#include "RenderTestSupport.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace weft::test {
namespace {

TEST_F(RenderTest, ContextReportsRendererAndCoreVersion) {
  EXPECT_FALSE(context->renderer().empty());
  EXPECT_NE(context->renderer(), "unknown");
  int major = 0, minor = 0;
  ASSERT_EQ(std::sscanf(context->glVersion().c_str(), "%d.%d", &major, &minor), 2) << context->glVersion();
  EXPECT_GE(major * 10 + minor, 33) << context->glVersion();
  EXPECT_TRUE(context->platform() == "surfaceless" || context->platform() == "device") << context->platform();
  std::printf("[ context  ] %s, OpenGL %s, EGL platform %s\n", context->renderer().c_str(),
              context->glVersion().c_str(), context->platform().c_str());
  EXPECT_EQ(context->width(), 320);
  EXPECT_EQ(context->height(), 240);
}

TEST_F(RenderTest, FramebufferResizesAndRejectsBadSizes) {
  ASSERT_TRUE(context->resizeFramebuffer(64, 32).ok());
  EXPECT_EQ(context->width(), 64);
  Image image;
  context->readPixels(image);
  EXPECT_EQ(image.width, 64);
  EXPECT_EQ(image.height, 32);

  const Status bad = context->resizeFramebuffer(0, 10);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("0x10"), std::string::npos) << bad.error().message;
  EXPECT_EQ(context->width(), 64);  // unchanged
}

TEST(EglContext, InvalidSettingsAreErrorsNotCrashes) {
  Result<EglContext> tiny = EglContext::create({.width = 0, .height = 10});
  ASSERT_FALSE(tiny.ok());
  EXPECT_NE(tiny.error().message.find("width"), std::string::npos);
  Result<EglContext> old = EglContext::create({.glMajorVersion = 2, .glMinorVersion = 1});
  ASSERT_FALSE(old.ok());
  EXPECT_NE(old.error().message.find("3.3"), std::string::npos);
}

// Two contexts share one EGL display; destroying one must leave the other drawing.
TEST_F(RenderTest, TwoContextsLiveSideBySide) {
  {
    Result<EglContext> second = EglContext::create({.width = 16, .height = 16});
    ASSERT_TRUE(second.ok()) << second.error().message;
    Image image;
    second->readPixels(image);
    EXPECT_EQ(image.width, 16);
  }
  ASSERT_TRUE(context->makeCurrent().ok());
  RenderSettings settings;
  settings.width = 32;
  settings.height = 32;
  auto renderer = ClothRenderer::create(*context, settings);
  ASSERT_TRUE(renderer.ok()) << renderer.error().message;
  Image image;
  ASSERT_TRUE(renderer->renderFrame({}, image).ok());
  EXPECT_TRUE(matches(image.pixel(5, 5), settings.background));
}

// The context can be moved (Result hands it over by move) without breaking a renderer built on it.
TEST_F(RenderTest, RendererSurvivesAMoveOfItsContext) {
  std::optional<EglContext> moved;  // declared first, so it outlives the renderer below
  {
    RenderSettings settings;
    settings.width = 32;
    settings.height = 24;
    auto renderer = ClothRenderer::create(*context, settings);
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    moved.emplace(std::move(*context));
    Image image;
    ASSERT_TRUE(renderer->renderFrame({}, image).ok());
    EXPECT_EQ(image.width, 32);
    EXPECT_EQ(moved->width(), 32);
  }
}

// With no EGL vendor library (libegl-mesa0 missing, or a stale __EGL_VENDOR_LIBRARY_FILENAMES),
// create() must return an error naming the packages, not crash. libglvnd reads the variable once
// per process, so this runs in a fresh child process ("threadsafe" death tests re-execute the
// binary).
TEST(EglContextDeathTest, MissingVendorLibraryGivesAnErrorNamingThePackages) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/weft_missing_vendor.json", 1);
        Result<EglContext> created = EglContext::create({.width = 8, .height = 8});
        std::fprintf(stderr, "%s\n", created.ok() ? "created a context without a vendor library"
                                                   : created.error().message.c_str());
        std::_Exit(created.ok() ? 1 : 0);
      },
      ::testing::ExitedWithCode(0),
      "no EGL display: install libegl-mesa0 and libgl1-mesa-dri .*__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent");
}

}  // namespace
}  // namespace weft::test
