// Shared fixtures of the collision tests: grid meshes, crumpling noise, brute-force references.
#pragma once

#include <weft/Math.h>
#include <weft/collision/Aabb.h>
#include <weft/collision/Bvh.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace weft::test {

/// A triangle mesh as plain arrays (what the collision module consumes).
struct MeshArrays {
  std::vector<Vec3> positions;
  std::vector<Index> indices;
  Index triangleCount() const { return static_cast<Index>(indices.size() / 3); }
  std::array<Index, 3> triangle(Index t) const {
    return {indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]};
  }
};

/// A flat grid in the z = 0 plane, columns × rows vertices, quads split along a diagonal like
/// ClothModel::grid (vertex = row · columns + column).
inline MeshArrays makeGrid(Index columns, Index rows, Real spacing) {
  MeshArrays mesh;
  for (Index r = 0; r < rows; ++r) {
    for (Index c = 0; c < columns; ++c) mesh.positions.emplace_back(c * spacing, r * spacing, 0.0);
  }
  for (Index r = 0; r + 1 < rows; ++r) {
    for (Index c = 0; c + 1 < columns; ++c) {
      const Index v00 = r * columns + c, v01 = v00 + 1, v10 = v00 + columns, v11 = v10 + 1;
      mesh.indices.insert(mesh.indices.end(), {v00, v01, v11, v00, v11, v10});
    }
  }
  return mesh;
}

/// Positions displaced by uniform noise in [−amplitude, amplitude]³ (deterministic per seed).
inline std::vector<Vec3> crumple(const std::vector<Vec3>& positions, Real amplitude,
                                 unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<Real> noise(-amplitude, amplitude);
  std::vector<Vec3> result = positions;
  for (Vec3& x : result) x += Vec3(noise(random), noise(random), noise(random));
  return result;
}

/// Folds a grid (in z = 0, x along columns) over a sinusoid in z plus noise: a crumpled sheet
/// whose far parts come close to each other.
inline std::vector<Vec3> fold(const std::vector<Vec3>& positions, Real amplitude, Real wavelength,
                              Real noiseAmplitude, unsigned seed) {
  std::vector<Vec3> result = crumple(positions, noiseAmplitude, seed);
  for (std::size_t i = 0; i < result.size(); ++i) {
    const Vec3& rest = positions[i];
    // Compress x and lift z: neighbouring folds come within reach of each other.
    result[i].x() = 0.3 * rest.x() + result[i].x() - rest.x();
    result[i].z() += amplitude * std::sin(2 * 3.14159265358979 * rest.x() / wavelength);
  }
  return result;
}

/// Box of one triangle swept from old to new positions, inflated by thickness.
inline Aabb sweptTriangleBox(const MeshArrays& mesh, Index t, const std::vector<Vec3>& oldX,
                             const std::vector<Vec3>& newX, Real thickness) {
  Aabb box;
  for (Index v : mesh.triangle(t)) {
    box.expand(oldX[v]);
    box.expand(newX[v]);
  }
  box.inflate(thickness);
  return box;
}

/// True when the two triangles share a vertex index.
inline bool shareVertex(const std::array<Index, 3>& a, const std::array<Index, 3>& b) {
  for (Index i : a) {
    for (Index j : b) {
      if (i == j) return true;
    }
  }
  return false;
}

}  // namespace weft::test
