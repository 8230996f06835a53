#include "MeshPreparation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <unordered_map>

namespace weft {
namespace {

std::string formatVec(const Vec3& v) {
  std::ostringstream text;
  text << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return text.str();
}

std::string formatReal(Real value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// Names vertices and triangles in the caller's numbering.
struct Namer {
  const std::vector<Index>& inputOfModel;
  Index vertex(Index model) const { return inputOfModel.empty() ? model : inputOfModel[model]; }
  std::string triangle(const std::vector<Index>& indices, std::size_t t) const {
    return "triangle " + std::to_string(t) + " (vertices " + std::to_string(vertex(indices[3 * t])) +
           ", " + std::to_string(vertex(indices[3 * t + 1])) + ", " +
           std::to_string(vertex(indices[3 * t + 2])) + ")";
  }
  std::string edge(Index a, Index b) const {
    return "edge (" + std::to_string(vertex(a)) + ", " + std::to_string(vertex(b)) + ")";
  }
};

// Step 1 of the design note: everything later passes index with.
Status checkShape(const TriangleMesh& mesh) {
  const std::size_t vertexCount = mesh.positions.size();
  if (vertexCount == 0 || mesh.indices.empty()) {
    return Error{"mesh is empty (" + std::to_string(vertexCount) + " vertices, " +
                 std::to_string(mesh.indices.size()) +
                 " indices): a cloth needs at least one triangle"};
  }
  if (vertexCount >= kInvalidIndex) {
    return Error{"mesh has " + std::to_string(vertexCount) + " vertices; at most " +
                 std::to_string(kInvalidIndex - 1) + " are supported: split the mesh"};
  }
  if (mesh.indices.size() % 3 != 0) {
    return Error{"mesh has " + std::to_string(mesh.indices.size()) +
                 " indices, not a multiple of 3: give three indices per triangle"};
  }
  if (mesh.indices.size() / 3 >= kInvalidIndex) {
    return Error{"mesh has " + std::to_string(mesh.indices.size() / 3) + " triangles; at most " +
                 std::to_string(kInvalidIndex - 1) + " are supported: split the mesh"};
  }
  for (std::size_t i = 0; i < vertexCount; ++i) {
    const Vec3& x = mesh.positions[i];
    if (!x.allFinite()) {
      return Error{"position of vertex " + std::to_string(i) + " is " + formatVec(x) +
                   ": every position must be finite"};
    }
    if (x.cwiseAbs().maxCoeff() > kMaxCoordinate) {
      return Error{"position of vertex " + std::to_string(i) + " is " + formatVec(x) +
                   " m, beyond the " + formatReal(kMaxCoordinate) +
                   " m a coordinate may have (kMaxCoordinate); model the cloth near the origin "
                   "and place it with ClothSettings::translation"};
    }
  }
  const std::size_t triangleCount = mesh.indices.size() / 3;
  for (std::size_t t = 0; t < triangleCount; ++t) {
    const Index a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
    const std::string name = "triangle " + std::to_string(t) + " (vertices " + std::to_string(a) +
                             ", " + std::to_string(b) + ", " + std::to_string(c) + ")";
    for (Index index : {a, b, c}) {
      if (index >= vertexCount) {
        return Error{name + ": index " + std::to_string(index) + " is out of range; the mesh has " +
                     std::to_string(vertexCount) + " vertices (valid indices 0.." +
                     std::to_string(vertexCount - 1) + ")"};
      }
    }
    if (a == b || b == c || a == c) {
      const Index repeated = (a == b || a == c) ? a : b;
      return Error{name + ": repeated vertex index " + std::to_string(repeated) +
                   "; every triangle needs three distinct vertices"};
    }
  }
  return Status::success();
}

// Step 2: fills modelOfInput and inputOfModel (both empty when nothing is welded).
Status weld(const TriangleMesh& mesh, const MeshSettings& settings,
            std::vector<Index>& modelOfInput, std::vector<Index>& inputOfModel) {
  const std::size_t vertexCount = mesh.positions.size();
  Vec3 lower = mesh.positions[0], upper = mesh.positions[0];
  for (const Vec3& p : mesh.positions) {
    lower = lower.cwiseMin(p);
    upper = upper.cwiseMax(p);
  }
  const Real diagonal = (upper - lower).norm();
  const Real tolerance = settings.weldTolerance * diagonal;
  if (!settings.weldVertices || !(tolerance > 0)) return Status::success();

  // Cells two tolerances wide: the ball of reach around a vertex touches at most 2 per axis.
  const Real cell = 2 * tolerance;
  constexpr Real kLargestCell = 4.5e15;  // exact in a double and an int64
  auto cellOf = [&](const Vec3& x, int axis) {
    const Real c = std::floor((x[axis] - lower[axis]) / cell);
    return std::int64_t(std::clamp(c, -kLargestCell, kLargestCell));
  };
  auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    std::uint64_t h = std::uint64_t(x) * 0x9E3779B97F4A7C15ull;
    h ^= std::uint64_t(y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= std::uint64_t(z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return h;
  };
  std::unordered_map<std::uint64_t, Index> headOfCell;
  std::vector<Index> nextInCell(vertexCount, kInvalidIndex);
  modelOfInput.assign(vertexCount, kInvalidIndex);
  inputOfModel.clear();
  Index welded = 0;
  for (std::size_t i = 0; i < vertexCount; ++i) {
    const Vec3& x = mesh.positions[i];
    std::int64_t first[3];
    int span[3];
    for (int axis = 0; axis < 3; ++axis) {
      first[axis] = cellOf(x, axis);
      // The neighbour cell below or above, whichever the ball of reach crosses into.
      const Real offset = (x[axis] - lower[axis]) / cell - Real(first[axis]);
      span[axis] = offset < 0.5 ? -1 : 1;
    }
    Index nearest = kInvalidIndex;
    for (int dz = 0; dz < 2; ++dz) {
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const auto found = headOfCell.find(key(first[0] + dx * span[0], first[1] + dy * span[1],
                                                 first[2] + dz * span[2]));
          if (found == headOfCell.end()) continue;
          for (Index kept = found->second; kept != kInvalidIndex; kept = nextInCell[kept]) {
            if (kept < nearest && (mesh.positions[kept] - x).norm() <= tolerance) nearest = kept;
          }
        }
      }
    }
    if (nearest != kInvalidIndex) {
      modelOfInput[i] = modelOfInput[nearest];
      ++welded;
      continue;
    }
    modelOfInput[i] = Index(inputOfModel.size());
    inputOfModel.push_back(Index(i));
    Index& head = headOfCell.try_emplace(key(first[0], first[1], first[2]), kInvalidIndex).first->second;
    nextInCell[i] = head;
    head = Index(i);
  }
  if (welded == 0) {
    modelOfInput.clear();
    inputOfModel.clear();
    return Status::success();
  }
  // A triangle whose corners welded together is smaller than the tolerance.
  const std::size_t triangleCount = mesh.indices.size() / 3;
  for (std::size_t t = 0; t < triangleCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      const Index a = mesh.indices[3 * t + k], b = mesh.indices[3 * t + (k + 1) % 3];
      if (modelOfInput[a] != modelOfInput[b]) continue;
      std::ostringstream text;
      text << "triangle " << t << " (vertices " << mesh.indices[3 * t] << ", "
           << mesh.indices[3 * t + 1] << ", " << mesh.indices[3 * t + 2] << "): its vertices " << a
           << " and " << b << " are " << (mesh.positions[a] - mesh.positions[b]).norm()
           << " m apart, within the weld tolerance of " << tolerance
           << " m (MeshSettings::weldTolerance = " << settings.weldTolerance << " of the "
           << diagonal << " m bounding-box diagonal), so welding would collapse it; remove the "
           << "triangle, or lower weldTolerance (0 or weldVertices = false keeps every vertex)";
      return Error{text.str()};
    }
  }
  return Status::success();
}

// Two triangles on the same three vertices (after welding, a double-sided copy of a surface).
Status checkDuplicates(const std::vector<Index>& indices, const Namer& names, bool welded) {
  struct Key {
    std::array<Index, 3> vertices;
    Index triangle;
    bool operator<(const Key& other) const {
      return vertices != other.vertices ? vertices < other.vertices : triangle < other.triangle;
    }
  };
  const std::size_t triangleCount = indices.size() / 3;
  std::vector<Key> keys(triangleCount);
  for (std::size_t t = 0; t < triangleCount; ++t) {
    keys[t] = {{indices[3 * t], indices[3 * t + 1], indices[3 * t + 2]}, Index(t)};
    std::sort(keys[t].vertices.begin(), keys[t].vertices.end());
  }
  std::sort(keys.begin(), keys.end());
  // The lowest-numbered repeat of any kind is reported, so the message does not depend on the sort.
  Index first = kInvalidIndex, repeat = kInvalidIndex;
  for (std::size_t k = 1; k < keys.size(); ++k) {
    if (keys[k].vertices != keys[k - 1].vertices || keys[k].triangle >= repeat) continue;
    std::size_t start = k - 1;
    while (start > 0 && keys[start - 1].vertices == keys[k].vertices) --start;
    first = keys[start].triangle;
    repeat = keys[k].triangle;
  }
  if (repeat == kInvalidIndex) return Status::success();
  return Error{names.triangle(indices, repeat) + ": the same three vertices form triangle " +
               std::to_string(first) + (welded ? " once coincident vertices are welded" : "") +
               "; remove the duplicate" +
               (welded ? " (a double-sided copy of the surface?)" : "")};
}

// One side of a mesh edge: triangle t runs from corner k to corner k + 1.
struct HalfEdge {
  std::uint64_t key;  // smaller vertex << 32 | larger vertex
  Index triangle;
  std::uint8_t corner;
  bool operator<(const HalfEdge& other) const {
    return key != other.key ? key < other.key : triangle < other.triangle;
  }
};

// Step 3: orients `indices` (and per-corner coordinates, when given) and finds bowties.
Status orient(std::vector<Index>& indices, std::size_t vertexCount, const MeshSettings& settings,
              const Namer& names, std::vector<Vec2>& perCorner, MeshImport& import,
              std::vector<Index>& bowties) {
  const std::size_t triangleCount = indices.size() / 3;
  std::vector<HalfEdge> halfEdges(3 * triangleCount);
  for (std::size_t t = 0; t < triangleCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      Index a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
      if (a > b) std::swap(a, b);
      halfEdges[3 * t + k] = {(std::uint64_t(a) << 32) | b, Index(t), std::uint8_t(k)};
    }
  }
  std::sort(halfEdges.begin(), halfEdges.end());

  // Across the edge of corner k of triangle t: the other triangle, and whether both run the edge
  // the same way (then one of them must be flipped).
  std::vector<Index> neighbour(3 * triangleCount, kInvalidIndex);
  std::vector<std::uint8_t> sameWay(3 * triangleCount, 0);
  auto runsUp = [&](const HalfEdge& h) {
    return indices[3 * h.triangle + h.corner] < indices[3 * h.triangle + (h.corner + 1) % 3];
  };
  for (std::size_t begin = 0; begin < halfEdges.size();) {
    std::size_t end = begin + 1;
    while (end < halfEdges.size() && halfEdges[end].key == halfEdges[begin].key) ++end;
    const Index a = Index(halfEdges[begin].key >> 32), b = Index(halfEdges[begin].key);
    if (end - begin >= 3 && settings.requireManifold) {
      return Error{names.edge(a, b) + " is shared by triangles " +
                   std::to_string(halfEdges[begin].triangle) + ", " +
                   std::to_string(halfEdges[begin + 1].triangle) + " and " +
                   std::to_string(halfEdges[begin + 2].triangle) +
                   ": non-manifold; bending needs at most two triangles per edge (split the "
                   "mesh there, or set MeshSettings::requireManifold = false)"};
    }
    if (end - begin == 2) {
      const HalfEdge& first = halfEdges[begin];
      const HalfEdge& second = halfEdges[begin + 1];
      const std::uint8_t same = runsUp(first) == runsUp(second);
      neighbour[3 * first.triangle + first.corner] = second.triangle;
      neighbour[3 * second.triangle + second.corner] = first.triangle;
      sameWay[3 * first.triangle + first.corner] = same;
      sameWay[3 * second.triangle + second.corner] = same;
    }
    begin = end;
  }
  halfEdges = {};

  // Breadth-first over each connected piece from its lowest-numbered triangle.
  constexpr std::int8_t kUnplaced = -1;
  std::vector<std::int8_t> flipped(triangleCount, kUnplaced);
  std::vector<Index> queue;
  for (std::size_t root = 0; root < triangleCount; ++root) {
    if (flipped[root] != kUnplaced) continue;
    ++import.components;
    flipped[root] = 0;
    queue.assign(1, Index(root));
    for (std::size_t next = 0; next < queue.size(); ++next) {
      const Index t = queue[next];
      for (int k = 0; k < 3; ++k) {
        const Index other = neighbour[3 * t + k];
        if (other == kInvalidIndex) continue;
        const Index a = indices[3 * t + k], b = indices[3 * t + (k + 1) % 3];
        if (sameWay[3 * t + k] && !settings.fixWinding) {
          return Error{"triangles " + std::to_string(std::min(t, other)) + " and " +
                       std::to_string(std::max(t, other)) + " run " + names.edge(a, b) +
                       " in the same direction, so their windings disagree; reverse one of "
                       "them, or set MeshSettings::fixWinding = true to flip them on import"};
        }
        const std::int8_t wanted = std::int8_t(flipped[t] ^ sameWay[3 * t + k]);
        if (flipped[other] == kUnplaced) {
          flipped[other] = wanted;
          queue.push_back(other);
        } else if (flipped[other] != wanted) {
          return Error{"triangles " + std::to_string(std::min(t, other)) + " and " +
                       std::to_string(std::max(t, other)) + " across " + names.edge(a, b) +
                       " cannot be wound consistently: the connected piece of triangle " +
                       std::to_string(root) +
                       " is non-orientable (a Möbius strip) and a cloth needs a front and a "
                       "back; cut the mesh along an edge of the twisted loop"};
        }
      }
    }
  }
  for (std::size_t t = 0; t < triangleCount; ++t) {
    if (!flipped[t]) continue;
    ++import.flippedTriangles;
    std::swap(indices[3 * t + 1], indices[3 * t + 2]);
    if (!perCorner.empty()) std::swap(perCorner[3 * t + 1], perCorner[3 * t + 2]);
  }

  // Bowties: the triangles around each vertex, grouped into fans through the manifold edges at
  // the vertex (corners are renumbered by the flips, so the edges are looked up by vertex).
  std::vector<std::size_t> offsets(vertexCount + 1, 0);
  for (Index corner : indices) ++offsets[corner + 1];
  for (std::size_t v = 0; v < vertexCount; ++v) offsets[v + 1] += offsets[v];
  std::vector<Index> around(indices.size());
  {
    std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t t = 0; t < triangleCount; ++t) {
      for (int k = 0; k < 3; ++k) around[fill[indices[3 * t + k]]++] = Index(t);
    }
  }
  // The neighbours were found before the flips: a flip swaps corners 1 and 2, which turns the
  // edges of corners 0 and 2 into each other. Only which triangles touch matters here.
  std::vector<Index> fan;
  std::vector<std::uint8_t> reached;
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const std::size_t begin = offsets[v], count = offsets[v + 1] - begin;
    if (count < 2) continue;
    reached.assign(count, 0);
    fan.assign(1, around[begin]);
    reached[0] = 1;
    for (std::size_t next = 0; next < fan.size(); ++next) {
      const Index t = fan[next];
      for (int k = 0; k < 3; ++k) {
        const Index other = neighbour[3 * t + k];
        if (other == kInvalidIndex) continue;
        // The edge between t and other holds v when v is a corner of both (they share an edge
        // and are not duplicates). around[begin, +count) is in triangle order.
        const auto first = around.begin() + std::ptrdiff_t(begin);
        const auto found = std::lower_bound(first, first + std::ptrdiff_t(count), other);
        if (found == first + std::ptrdiff_t(count) || *found != other) continue;
        const std::size_t j = std::size_t(found - first);
        if (reached[j]) continue;
        reached[j] = 1;
        fan.push_back(other);
      }
    }
    if (fan.size() == count) continue;
    if (!settings.requireManifold) {
      bowties.push_back(Index(v));
      continue;
    }
    const std::size_t outside = std::size_t(std::find(reached.begin(), reached.end(), 0) - reached.begin());
    return Error{"vertex " + std::to_string(names.vertex(Index(v))) +
                 " is a bowtie: triangles " + std::to_string(around[begin]) + " and " +
                 std::to_string(around[begin + outside]) +
                 " lie in separate fans that meet only at this vertex; bending needs one fan per "
                 "vertex: give each fan its own vertex, join the fans with triangles, or set "
                 "MeshSettings::requireManifold = false"};
  }
  return Status::success();
}

}  // namespace

Result<PreparedMesh> prepareMesh(const TriangleMesh& mesh, const MeshSettings& settings) {
  if (Status shape = checkShape(mesh); !shape.ok()) return shape.error();
  PreparedMesh prepared;
  std::vector<Index> modelOfInput;
  if (Status welded = weld(mesh, settings, modelOfInput, prepared.inputOfModel); !welded.ok()) {
    return welded.error();
  }
  TriangleMesh& out = prepared.mesh;
  if (modelOfInput.empty()) {
    out = mesh;
  } else {
    out.positions.reserve(prepared.inputOfModel.size());
    for (Index input : prepared.inputOfModel) out.positions.push_back(mesh.positions[input]);
    out.indices.reserve(mesh.indices.size());
    for (Index input : mesh.indices) out.indices.push_back(modelOfInput[input]);
    // The welded copies of a seam vertex carry different (u, v): keep them per corner.
    if (!mesh.materialCoordinates.empty()) {
      prepared.perCornerMaterialCoordinates.reserve(mesh.indices.size());
      for (Index input : mesh.indices) {
        prepared.perCornerMaterialCoordinates.push_back(mesh.materialCoordinates[input]);
      }
    }
    prepared.import.weldedVertices = Index(mesh.positions.size() - prepared.inputOfModel.size());
    prepared.import.modelVertexOfInput = std::move(modelOfInput);
  }
  const Namer names{prepared.inputOfModel};
  if (Status unique = checkDuplicates(out.indices, names, !prepared.inputOfModel.empty());
      !unique.ok()) {
    return unique.error();
  }
  if (Status oriented = orient(out.indices, out.positions.size(), settings, names,
                               prepared.perCornerMaterialCoordinates, prepared.import,
                               prepared.bowtieVertices);
      !oriented.ok()) {
    return oriented.error();
  }
  return prepared;
}

}  // namespace weft
