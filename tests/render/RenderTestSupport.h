// Helpers shared by the render tests: grid cloths, a draped curtain, pixel statistics and a context
// fixture that fails without an EGL display (skips only when WEFT_ALLOW_MISSING_EGL=1).
#pragma once

#include <weft/render/ClothRenderer.h>
#include <weft/render/EglContext.h>
#include <weft/render/Image.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace weft::test {

/// A cloth made of a columns × rows vertex grid, for drawing.
struct GridCloth {
  std::vector<Vec3> positions;
  std::vector<Index> indices;
  std::vector<Vec3> normals;  ///< empty unless filled by the test

  ClothRenderView view() const { return {positions, normals, indices}; }
};

/// Grid of columns × rows vertices placed by place(u, v), u and v in [0, 1]; every quad is split in
/// two triangles that wind counter-clockwise when u runs along +x and v along +y, seen from +z.
inline GridCloth makeGrid(int columns, int rows, const std::function<Vec3(double u, double v)>& place) {
  GridCloth grid;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      grid.positions.push_back(place(double(i) / (columns - 1), double(j) / (rows - 1)));
    }
  }
  const auto at = [&](int i, int j) { return static_cast<Index>(j * columns + i); };
  for (int j = 0; j + 1 < rows; ++j) {
    for (int i = 0; i + 1 < columns; ++i) {
      grid.indices.insert(grid.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      grid.indices.insert(grid.indices.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  }
  return grid;
}

/// Flat square of side metres centred at the origin in the z = 0 plane, front facing +z.
inline GridCloth makeFlatSquare(double side, int verticesPerSide = 11) {
  return makeGrid(verticesPerSide, verticesPerSide,
                  [&](double u, double v) { return Vec3((u - 0.5) * side, (v - 0.5) * side, 0.0); });
}

/// The benchmark curtain (2 m × 1.5 m, x in [−1, 1], y in [0.5, 2]) hanging in folds that
/// deepen towards the hem and swing back at the bottom. The folds lean sideways (their top-view
/// section is a sheared sine, x non-monotone near the hem), so seen from the front some flanks
/// overhang and show the back of the cloth, as real gathered curtains do.
inline GridCloth makeDrapedCurtain(int columns = 41, int rows = 31) {
  return makeGrid(columns, rows, [](double u, double v) {
    const double hang = 1.0 - v;                   // 0 at the rod, 1 at the hem
    const double phase = 2 * std::numbers::pi * 5 * u;  // five folds across the width
    const double depth = 0.05 + 0.10 * hang;       // m, fold amplitude
    const double lean = 0.03 + 0.07 * hang;        // m, sideways shear; overhangs beyond 2 / (2π · 5) ≈ 0.064 m
    const double x = -1.0 + 2.0 * u - lean * std::sin(phase);
    const double y = 0.5 + 1.5 * v;
    const double z = depth * std::sin(phase) - 0.25 * hang * hang;
    return Vec3(x, y, z);
  });
}

/// Byte value a 0–1 colour channel is stored as in an RGBA8 framebuffer.
inline int toByte(float channel) { return static_cast<int>(std::lround(channel * 255.0f)); }

/// True when pixel p equals colour c within tolerance per channel (in 0–255 steps).
inline bool matches(const Rgba8& p, const ColorRgb& c, int tolerance = 1) {
  return std::abs(p[0] - toByte(c.r)) <= tolerance && std::abs(p[1] - toByte(c.g)) <= tolerance &&
         std::abs(p[2] - toByte(c.b)) <= tolerance;
}

/// Share of the image's pixels that differ from the background colour.
inline double coverage(const Image& image, const ColorRgb& background) {
  std::size_t covered = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) covered += matches(image.pixel(x, y), background, 0) ? 0 : 1;
  }
  return double(covered) / (double(image.width) * image.height);
}

/// Pixel (x right, y down from the top row) where the pinhole camera of settings sees point p.
inline std::pair<int, int> projectToPixel(const RenderSettings& settings, const Vec3& p) {
  const CameraSettings& c = settings.camera;
  const Vec3 forward = (c.target - c.eye).normalized();
  const Vec3 right = forward.cross(c.up).normalized();
  const Vec3 up = right.cross(forward);
  const Vec3 d = p - c.eye;
  const double halfHeight = d.dot(forward) * std::tan(c.verticalFovDegrees * std::numbers::pi / 360.0);
  const double aspect = double(settings.width) / settings.height;
  const double ndcX = d.dot(right) / (halfHeight * aspect);
  const double ndcY = d.dot(up) / halfHeight;
  return {int((ndcX + 1) / 2 * settings.width), int((1 - ndcY) / 2 * settings.height)};
}

/// Where tests write pictures for people to look at: $WEFT_RENDER_OUTPUT_DIR or <tmp>/weft-render.
inline std::filesystem::path outputDir() {
  const char* configured = std::getenv("WEFT_RENDER_OUTPUT_DIR");
  std::filesystem::path dir = configured ? std::filesystem::path(configured)
                                         : std::filesystem::temp_directory_path() / "weft-render";
  std::filesystem::create_directories(dir);
  return dir;
}

/// Debian packages the render tests need: Mesa's EGL and software rasteriser to run, the
/// libglvnd headers and stubs to build.
inline constexpr const char* kEglPackages =
    "apt-get install libegl-mesa0 libgl1-mesa-dri (to build: libegl-dev libgl-dev libopengl-dev)";

/// Creates a context. A machine without an EGL display fails the test, naming the packages to
/// install: the suite must really render. WEFT_ALLOW_MISSING_EGL=1 turns that failure into a skip,
/// for a developer without Mesa. Any other context failure is a test failure.
class RenderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Result<EglContext> created = EglContext::create({.width = 320, .height = 240});
    if (!created) {
      const std::string& message = created.error().message;
      const bool noDisplay = message.rfind("no EGL display", 0) == 0;
      const char* allow = std::getenv("WEFT_ALLOW_MISSING_EGL");
      if (noDisplay && allow != nullptr && std::string(allow) == "1") {
        GTEST_SKIP() << "EGL unavailable (WEFT_ALLOW_MISSING_EGL=1): " << message;
      }
      if (noDisplay) {
        FAIL() << "the render tests need an EGL display: " << kEglPackages
               << "; or set WEFT_ALLOW_MISSING_EGL=1 to skip them. " << message;
      }
      FAIL() << message;
    }
    context.emplace(std::move(created).value());
  }

  std::optional<EglContext> context;
};

}  // namespace weft::test
