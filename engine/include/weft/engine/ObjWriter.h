// ObjWriter: a cloth's current shape as a Wavefront OBJ file (positions, vertex normals,
// triangles), for frame export to other tools (Blender, MeshLab) and for round trips through
// ClothModel::readObj().
//
// Numbers are written in their shortest round-trip form (std::to_chars), so reading the file back
// gives the same doubles bit for bit. Faces reference the normal of the same index ("f a//a ...").
#pragma once

#include <weft/Math.h>
#include <weft/Result.h>
#include <weft/engine/RenderView.h>

#include <span>
#include <string>
#include <string_view>

namespace weft {

/// The OBJ text of a mesh: "v" lines, "vn" lines (when normals is not empty), "f" lines.
/// Errors: an index count that is not a multiple of three, an index out of range, a normal count
/// other than 0 or the vertex count, a non-finite value.
Result<std::string> formatObj(std::span<const Vec3> positions, std::span<const Vec3> normals,
                              std::span<const Index> indices, std::string_view comment = {});

/// Writes formatObj() to `path` (the folder must exist). The error names the path and the reason.
Status writeObj(const std::string& path, std::span<const Vec3> positions,
                std::span<const Vec3> normals, std::span<const Index> indices,
                std::string_view comment = {});

/// Writes a cloth as World::renderView() shows it.
Status writeObj(const std::string& path, const ClothRenderView& view, std::string_view comment = {});

}  // namespace weft
