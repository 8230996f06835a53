#include "PrimitiveMesh.h"

#include <cmath>
#include <numbers>

namespace weft {
namespace {

void addVertex(PrimitiveMesh& mesh, const Vec3& position, const Vec3& normal) {
  for (int i = 0; i < 3; ++i) mesh.vertices.push_back(static_cast<float>(position[i]));
  for (int i = 0; i < 3; ++i) mesh.vertices.push_back(static_cast<float>(normal[i]));
}

void addTriangle(PrimitiveMesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  mesh.indices.insert(mesh.indices.end(), {a, b, c});
}

}  // namespace

PrimitiveMesh makeSphereMesh(int slices, int stacks) {
  PrimitiveMesh mesh;
  // Grid of (stacks + 1) rings × (slices + 1) columns; the seam column is duplicated.
  for (int stack = 0; stack <= stacks; ++stack) {
    const double polar = std::numbers::pi * stack / stacks;  // 0 at +y
    for (int slice = 0; slice <= slices; ++slice) {
      const double azimuth = 2.0 * std::numbers::pi * slice / slices;
      const Vec3 p(std::sin(polar) * std::sin(azimuth), std::cos(polar), std::sin(polar) * std::cos(azimuth));
      addVertex(mesh, p, p);
    }
  }
  const auto vertex = [&](int stack, int slice) { return static_cast<std::uint32_t>(stack * (slices + 1) + slice); };
  for (int stack = 0; stack < stacks; ++stack) {
    for (int slice = 0; slice < slices; ++slice) {
      // Counter-clockwise from outside: going down (+stack) then along +azimuth.
      const std::uint32_t a = vertex(stack, slice), b = vertex(stack + 1, slice);
      const std::uint32_t c = vertex(stack + 1, slice + 1), d = vertex(stack, slice + 1);
      if (stack != 0) addTriangle(mesh, a, b, d);
      if (stack != stacks - 1) addTriangle(mesh, b, c, d);
    }
  }
  return mesh;
}

PrimitiveMesh makeCylinderMesh(int slices) {
  PrimitiveMesh mesh;
  for (int slice = 0; slice <= slices; ++slice) {
    const double azimuth = 2.0 * std::numbers::pi * slice / slices;
    const Vec3 n(std::sin(azimuth), 0.0, std::cos(azimuth));
    addVertex(mesh, n, n);                    // bottom, y = 0
    addVertex(mesh, n + Vec3::UnitY(), n);    // top, y = 1
  }
  for (int slice = 0; slice < slices; ++slice) {
    const auto bottom = static_cast<std::uint32_t>(2 * slice);
    const std::uint32_t top = bottom + 1, nextBottom = bottom + 2, nextTop = bottom + 3;
    addTriangle(mesh, bottom, nextBottom, top);
    addTriangle(mesh, top, nextBottom, nextTop);
  }
  return mesh;
}

PrimitiveMesh makeQuadMesh() {
  PrimitiveMesh mesh;
  const Vec3 up = Vec3::UnitY();
  addVertex(mesh, Vec3(-1, 0, -1), up);
  addVertex(mesh, Vec3(-1, 0, 1), up);
  addVertex(mesh, Vec3(1, 0, 1), up);
  addVertex(mesh, Vec3(1, 0, -1), up);
  addTriangle(mesh, 0, 1, 2);
  addTriangle(mesh, 0, 2, 3);
  return mesh;
}

PrimitiveMesh makeCubeMesh() {
  PrimitiveMesh mesh;
  // Each face: normal n and two in-plane axes u, v with u × v = n, so (−u−v, u−v, u+v, −u+v) is
  // counter-clockwise seen from outside.
  const Vec3 normals[6] = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  for (const Vec3& n : normals) {
    const Vec3 u = Vec3(n.y(), n.z(), n.x());  // a different axis, ± like n
    const Vec3 v = n.cross(u);
    const Vec3 uu = v.cross(n);  // makes (uu, v, n) right-handed: uu × v = n
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size() / PrimitiveMesh::kFloatsPerVertex);
    addVertex(mesh, n - uu - v, n);
    addVertex(mesh, n + uu - v, n);
    addVertex(mesh, n + uu + v, n);
    addVertex(mesh, n - uu + v, n);
    addTriangle(mesh, base, base + 1, base + 2);
    addTriangle(mesh, base, base + 2, base + 3);
  }
  return mesh;
}

}  // namespace weft
