// PNG through libpng's simplified API: no setjmp/longjmp in our code, errors come back as text in
// png_image::message. The file is opened here with fopen so a bad path reports errno's reason.
#include <weft/render/Png.h>

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace weft {
namespace {

struct FileCloser {
  void operator()(std::FILE* file) const { std::fclose(file); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

}  // namespace

Status writePng(const std::string& path, const Image& image, PngCompression compression) {
  if (image.empty() || image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4) {
    return Error{"writePng '" + path + "': image is empty or its pixel buffer does not match " +
                 std::to_string(image.width) + "x" + std::to_string(image.height) + " RGBA8"};
  }
  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (!file) {
    return Error{"writePng: cannot open '" + path + "' for writing: " + std::strerror(errno)};
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGBA;
  if (compression == PngCompression::kFast) png.flags |= PNG_IMAGE_FLAG_FAST;
  const int ok = png_image_write_to_stdio(&png, file.get(), 0, image.rgba.data(), 0, nullptr);
  const std::string reason = png.message;
  png_image_free(&png);
  if (!ok) return Error{"writePng: failed to encode '" + path + "': " + reason};
  // Flush explicitly so a full disk shows up as an error here, not as a silent short file.
  if (std::fflush(file.get()) != 0 || std::ferror(file.get())) {
    return Error{"writePng: failed to write '" + path + "': " + std::strerror(errno)};
  }
  if (std::fclose(file.release()) != 0) {
    return Error{"writePng: failed to close '" + path + "': " + std::strerror(errno)};
  }
  return {};
}

Result<Image> readPng(const std::string& path) {
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) {
    return Error{"readPng: cannot open '" + path + "': " + std::strerror(errno)};
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_stdio(&png, file.get())) {
    const std::string reason = png.message;
    png_image_free(&png);
    return Error{"readPng: '" + path + "' is not a readable PNG: " + reason};
  }
  png.format = PNG_FORMAT_RGBA;  // libpng converts grey, palette and 16-bit input
  Image image;
  image.resize(static_cast<int>(png.width), static_cast<int>(png.height));
  if (!png_image_finish_read(&png, nullptr, image.rgba.data(), 0, nullptr)) {
    const std::string reason = png.message;
    png_image_free(&png);
    return Error{"readPng: failed to decode '" + path + "': " + reason};
  }
  return image;
}

}  // namespace weft
