// Read-only views of simulation state for drawing. The engine includes no graphics header;
// renderers (weft::render, or a game's own) read these spans, which stay valid until the next
// World::step() or until the cloth is destroyed.
#pragma once

#include <weft/Math.h>

#include <span>

namespace weft {

/// What a renderer needs to draw one cloth.
struct ClothRenderView {
  std::span<const Vec3> positions;  ///< m, one per vertex
  std::span<const Vec3> normals;    ///< unit vertex normals (area-weighted); may be empty
  std::span<const Index> indices;   ///< three per triangle, counter-clockwise seen from the front
};

}  // namespace weft
