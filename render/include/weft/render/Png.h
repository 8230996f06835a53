// PNG files through libpng's simplified API (png_image), RGBA8 only.
//
// Encoding a 1280×720 frame takes tens of milliseconds, which is longer than a frame: keep it off
// the frame loop (ImageSequenceWriter does it on its own thread).
#pragma once

#include <weft/Result.h>
#include <weft/render/Image.h>

#include <string>

namespace weft {

/// Speed against size for PNG encoding.
enum class PngCompression {
  kFast,     ///< libpng's fast mode: larger files, a few times quicker to write (frame capture)
  kDefault,  ///< zlib's default level: smaller files (reference images)
};

/// Writes image as an 8-bit RGBA PNG; the error names the path and the reason (e.g. a missing
/// directory or no permission). An empty image is an error.
Status writePng(const std::string& path, const Image& image,
                PngCompression compression = PngCompression::kDefault);

/// Reads any PNG (grey, palette, 16-bit, with or without alpha) and converts it to RGBA8;
/// the error names the path and the reason.
Result<Image> readPng(const std::string& path);

}  // namespace weft
