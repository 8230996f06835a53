// Shared fixtures of the collision tests: grid, box and cylinder meshes, crumpling noise,
// brute-force references.
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

/// A closed box [−h, h] as 12 triangles (counter-clockwise seen from outside).
inline MeshArrays makeBox(const Vec3& h) {
  MeshArrays box;
  for (int corner = 0; corner < 8; ++corner) {
    box.positions.emplace_back((corner & 4) ? h.x() : -h.x(), (corner & 2) ? h.y() : -h.y(),
                               (corner & 1) ? h.z() : -h.z());
  }
  box.indices = {4, 6, 7, 4, 7, 5,  0, 1, 3, 0, 3, 2,  2, 3, 7, 2, 7, 6,
                 0, 4, 5, 0, 5, 1,  1, 5, 7, 1, 7, 3,  0, 2, 6, 0, 6, 4};
  return box;
}

/// A closed cylinder of `radius` along y, `halfHeight` each way: `segments` round (vertices
/// k and segments + k on the bottom and top rings), one band of quads, a fan on each cap
/// (counter-clockwise seen from outside).
inline MeshArrays makeCylinder(Real radius, Real halfHeight, Index segments) {
  MeshArrays cylinder;
  for (Real y : {-halfHeight, halfHeight}) {
    for (Index k = 0; k < segments; ++k) {
      const Real azimuth = 2 * M_PI * Real(k) / Real(segments);
      cylinder.positions.emplace_back(radius * std::cos(azimuth), y, -radius * std::sin(azimuth));
    }
  }
  const Index bottom = Index(cylinder.positions.size());
  cylinder.positions.emplace_back(0, -halfHeight, 0);
  cylinder.positions.emplace_back(0, halfHeight, 0);
  const Index top = bottom + 1;
  for (Index k = 0; k < segments; ++k) {
    const Index next = (k + 1) % segments;
    cylinder.indices.insert(cylinder.indices.end(),
                            {k, next, segments + next, k, segments + next, segments + k, top,
                             segments + k, segments + next, bottom, next, k});
  }
  return cylinder;
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
