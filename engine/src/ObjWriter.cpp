#include <weft/engine/ObjWriter.h>

#include <algorithm>
#include <charconv>
#include <cerrno>
#include <cstring>
#include <fstream>

namespace weft {
namespace {

void appendNumber(std::string& text, Real value) {
  char buffer[32];
  const std::to_chars_result written = std::to_chars(buffer, buffer + sizeof buffer, value);
  text.append(buffer, written.ptr);
}

void appendVector(std::string& text, std::string_view tag, const Vec3& v) {
  text += tag;
  for (int k = 0; k < 3; ++k) {
    text += ' ';
    appendNumber(text, v[k]);
  }
  text += '\n';
}

}  // namespace

Result<std::string> formatObj(std::span<const Vec3> positions, std::span<const Vec3> normals,
                              std::span<const Index> indices, std::string_view comment) {
  if (indices.size() % 3 != 0) {
    return Error{"OBJ export: " + std::to_string(indices.size()) +
                 " indices is not a multiple of three; give three per triangle"};
  }
  if (!normals.empty() && normals.size() != positions.size()) {
    return Error{"OBJ export: " + std::to_string(normals.size()) + " normals for " +
                 std::to_string(positions.size()) + " vertices; give one per vertex or none"};
  }
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!positions[i].allFinite() || (!normals.empty() && !normals[i].allFinite())) {
      return Error{"OBJ export: vertex " + std::to_string(i) +
                   " has a NaN or infinite position or normal; export a finite state"};
    }
  }
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (indices[k] >= positions.size()) {
      return Error{"OBJ export: triangle " + std::to_string(k / 3) + " uses vertex " +
                   std::to_string(indices[k]) + " of " + std::to_string(positions.size())};
    }
  }
  std::string text;
  text.reserve(positions.size() * 2 * 64 + indices.size() * 12 + 64);
  if (!comment.empty()) {
    // One comment line per line of the comment, so a newline in it cannot start an OBJ statement.
    std::size_t start = 0;
    while (start <= comment.size()) {
      const std::size_t end = std::min(comment.find('\n', start), comment.size());
      text += "# ";
      text += comment.substr(start, end - start);
      text += '\n';
      start = end + 1;
    }
  }
  for (const Vec3& x : positions) appendVector(text, "v", x);
  for (const Vec3& n : normals) appendVector(text, "vn", n);
  const bool withNormals = !normals.empty();
  for (std::size_t k = 0; k < indices.size(); k += 3) {
    text += 'f';
    for (std::size_t c = 0; c < 3; ++c) {
      const std::string index = std::to_string(indices[k + c] + std::uint64_t(1));  // OBJ counts from 1
      text += ' ';
      text += index;
      if (withNormals) {
        text += "//";
        text += index;
      }
    }
    text += '\n';
  }
  return text;
}

Status writeObj(const std::string& path, std::span<const Vec3> positions,
                std::span<const Vec3> normals, std::span<const Index> indices,
                std::string_view comment) {
  Result<std::string> text = formatObj(positions, normals, indices, comment);
  if (!text.ok()) return Error{text.error().message + " (file '" + path + "')"};
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file) {
    return Error{"cannot write OBJ file '" + path + "': " + std::strerror(errno) +
                 "; check that the folder exists and is writable"};
  }
  file.write(text->data(), std::streamsize(text->size()));
  file.close();
  if (!file) {
    return Error{"writing OBJ file '" + path + "' failed (disk full?); check the free space"};
  }
  return Status::success();
}

Status writeObj(const std::string& path, const ClothRenderView& view, std::string_view comment) {
  return writeObj(path, view.positions, view.normals, view.indices, comment);
}

}  // namespace weft
