// Image: an RGBA8 picture in memory, the unit of frame capture.
//
// Rows run top-down (row 0 is the top of the picture, as in PNG and video), so what OpenGL reads
// bottom-up is flipped once, in EglContext::readPixels(), and nowhere else.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace weft {

/// One pixel: red, green, blue, alpha, 0–255 each.
using Rgba8 = std::array<std::uint8_t, 4>;

/// An RGBA8 image with top-down rows and no padding (stride = 4 · width bytes).
struct Image {
  int width = 0;                    ///< pixels
  int height = 0;                   ///< pixels
  std::vector<std::uint8_t> rgba;   ///< 4 · width · height bytes, row 0 at the top

  /// Resizes to width × height; keeps the allocation when it is already large enough.
  void resize(int newWidth, int newHeight) {
    width = newWidth;
    height = newHeight;
    rgba.resize(static_cast<std::size_t>(newWidth) * static_cast<std::size_t>(newHeight) * 4);
  }

  /// True when the image holds no pixels.
  bool empty() const { return width <= 0 || height <= 0; }

  /// Byte offset of pixel (x, y), x to the right, y down from the top row.
  std::size_t offset(int x, int y) const {
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4;
  }

  /// The pixel at (x, y); the caller keeps 0 ≤ x < width and 0 ≤ y < height.
  Rgba8 pixel(int x, int y) const {
    const std::size_t i = offset(x, y);
    return {rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]};
  }

  /// Same size and the same bytes.
  friend bool operator==(const Image& a, const Image& b) = default;
};

}  // namespace weft
