// Wavefront OBJ text → TriangleMesh (positions and triangles), for ClothModel::parseObj().
//
// Design note
// -----------
// Written for input that cannot be trusted: a single pass over the text that reads only what a
// cloth needs ("v" positions and "f" faces) and refuses, naming the line, everything a general
// reader would quietly turn into something else: a coordinate that is not a finite number
// ("nan", "inf", "1e400"), a vertex index of zero, beyond the file's vertices or too large for
// any integer, a face of fewer than three corners, a "v" line without three numbers. Every
// other statement (vt, vn, o, g, s, usemtl, mtllib, l, p, ...) is skipped: a cloth model takes
// nothing from them. Memory grows with the text only, never with the values in it.
//
// Polygons: a quad is split along its shorter diagonal; a polygon of up to kMaxEarClippedCorners
// corners is ear-clipped in the plane of its Newell normal (so a concave outline stays inside
// itself); larger ones, and outlines that clipping cannot finish (self-intersecting), are fanned
// from their first corner. Faces keep the winding the file gives them.
//
// Rejected: tinyobjloader, which reads "nan" as 0, turns an index beyond int into the last
// vertex (atoi overflow), and drops malformed faces with a warning.
#pragma once

#include <weft/engine/ClothModel.h>

#include <string_view>

namespace weft {

/// Polygons with more corners than this are fanned instead of ear-clipped (O(n³) worst case).
inline constexpr std::size_t kMaxEarClippedCorners = 64;

/// Parses OBJ text; `source` names it in messages ("OBJ file 'cape.obj'").
Result<TriangleMesh> parseObjText(std::string_view text, std::string_view source);

}  // namespace weft
