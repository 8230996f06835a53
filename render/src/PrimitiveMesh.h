// Unit meshes for collider primitives, built once on the CPU and placed with a model matrix.
// Vertices are interleaved float position (x, y, z) and normal (nx, ny, nz); triangles wind
// counter-clockwise seen from outside, like the cloth.
#pragma once

#include <weft/Math.h>

#include <cstdint>
#include <vector>

namespace weft {

/// Interleaved vertices and triangle indices of one mesh.
struct PrimitiveMesh {
  static constexpr int kFloatsPerVertex = 6;  ///< position xyz, normal xyz
  std::vector<float> vertices;                ///< kFloatsPerVertex floats per vertex
  std::vector<std::uint32_t> indices;         ///< three per triangle
};

/// Sphere of radius 1 at the origin, slices around the y axis and stacks from pole to pole.
PrimitiveMesh makeSphereMesh(int slices = 32, int stacks = 16);
/// Open cylinder of radius 1 around the y axis, from y = 0 to y = 1.
PrimitiveMesh makeCylinderMesh(int slices = 32);
/// Square from −1 to 1 in x and z at y = 0, facing +y.
PrimitiveMesh makeQuadMesh();
/// Cube from −1 to 1 on each axis, with flat faces (4 vertices per face).
PrimitiveMesh makeCubeMesh();

}  // namespace weft
