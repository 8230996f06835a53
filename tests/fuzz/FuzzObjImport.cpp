// libFuzzer target: OBJ text → ClothModel::parseObj() → ClothModel::fromMesh(). Whatever the
// bytes, both must return a value or an error: no crash, no sanitizer report, no hang.
#include <weft/engine/ClothModel.h>

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  weft::Result<weft::TriangleMesh> mesh = weft::ClothModel::parseObj(text, "fuzz input");
  if (!mesh.ok()) return 0;
  for (bool manifold : {true, false}) {
    weft::MeshSettings settings;
    settings.requireManifold = manifold;
    weft::Result<weft::ClothModel> model = weft::ClothModel::fromMesh(mesh.value(), settings);
    if (model.ok() && model->vertexCount() == 0) __builtin_trap();  // a model always has vertices
  }
  return 0;
}
