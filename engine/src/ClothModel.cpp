// ClothModel construction: validation first, then rest state, then derived topology.
//
// Validation rejects, with a message naming the element, everything that would later turn into
// a singular matrix or a NaN: empty meshes, index counts that are not a multiple of three,
// out-of-range or repeated indices, non-finite or far-away positions, zero-area triangles,
// duplicated triangles, vertices used by no triangle (they would have zero mass) and, when
// bending needs it, edges shared by more than two triangles and bowtie vertices. fromMesh()
// welds coincident vertices and orients the triangles first (MeshPreparation.h); sizes are
// checked against the 32-bit index range and the available memory before anything is allocated.
//
// Everything derived (edges, hinges, springs) is built in the order of the input triangles, so a
// model built twice from the same mesh is identical element for element: later stages rely on
// this for determinism.
#include <weft/engine/ClothModel.h>

#include "MeshPreparation.h"
#include "ObjParser.h"
#include "forces/BaraffWitkin.h"
#include "forces/IsometricBending.h"

#include <weft/engine/InputFile.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

namespace weft {
namespace {

std::uint64_t edgeKey(Index a, Index b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 32) | b;
}

std::string describeTriangle(Index t, Index a, Index b, Index c) {
  std::ostringstream text;
  text << "triangle " << t << " (vertices " << a << ", " << b << ", " << c << ")";
  return text.str();
}

std::string formatVec(const Vec3& v) {
  std::ostringstream text;
  text << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return text.str();
}

// Flattens one triangle isometrically into its own plane: u along the warp direction projected
// into the plane (or along the first edge when the warp is nearly normal to the triangle).
std::array<Vec2, 3> flattenTriangle(const Vec3& x0, const Vec3& x1, const Vec3& x2,
                                    const Vec3& warpDirection) {
  const Vec3 normal = (x1 - x0).cross(x2 - x0).normalized();
  Vec3 uAxis = warpDirection - warpDirection.dot(normal) * normal;
  // 0.1 ≈ the warp lies within ~6° of the normal: the projection no longer means much.
  if (uAxis.norm() < 0.1 * warpDirection.norm()) uAxis = x1 - x0;
  uAxis.normalize();
  const Vec3 vAxis = normal.cross(uAxis);
  auto project = [&](const Vec3& x) { return Vec2((x - x0).dot(uAxis), (x - x0).dot(vAxis)); };
  return {Vec2::Zero(), project(x1), project(x2)};
}

}  // namespace

std::uint64_t ClothModel::estimatedBuildBytes(std::uint64_t vertices, std::uint64_t triangles) {
  // Measured peaks (bench/results/memory-footprint.md): grid() 1.2-1.5 kB and fromMesh()
  // 1.7-1.9 kB a vertex on meshes of 2 triangles a vertex; a third more for hash tables that
  // grow in steps.
  constexpr std::uint64_t kBytesPerVertex = 1536, kBytesPerTriangle = 512;
  return kBytesPerVertex * vertices + kBytesPerTriangle * triangles;
}

std::vector<Real> ClothModel::vertexMasses(Real arealDensity) const {
  std::vector<Real> masses(m_vertexAreas.size());
  for (std::size_t i = 0; i < masses.size(); ++i) masses[i] = arealDensity * m_vertexAreas[i];
  return masses;
}

Result<ClothModel> ClothModel::grid(const GridSettings& settings) {
  if (settings.columns < 2 || settings.rows < 2) {
    return Error{"grid of " + std::to_string(settings.columns) + " x " +
                 std::to_string(settings.rows) +
                 " vertices: a cloth grid needs at least 2 columns and 2 rows"};
  }
  if (!(std::isfinite(settings.width) && settings.width > 0) ||
      !(std::isfinite(settings.height) && settings.height > 0)) {
    std::ostringstream text;
    text << "grid size " << settings.width << " m x " << settings.height
         << " m: width and height must be finite and greater than zero";
    return Error{text.str()};
  }
  if (!settings.origin.allFinite() || !settings.widthAxis.allFinite() ||
      !settings.heightAxis.allFinite()) {
    return Error{"grid origin or axes contain NaN or infinity; give finite vectors"};
  }
  const Vec3 widthAxis = settings.widthAxis.normalized();
  const Vec3 heightAxis = settings.heightAxis.normalized();
  if (std::abs(widthAxis.dot(heightAxis)) > 1e-6 || settings.widthAxis.norm() == 0 ||
      settings.heightAxis.norm() == 0) {
    return Error{"grid widthAxis " + formatVec(settings.widthAxis) + " and heightAxis " +
                 formatVec(settings.heightAxis) + " must be non-zero and perpendicular"};
  }

  // Every vertex lies within |origin| + width + height of the origin (the axes are unit).
  const Real farthest = settings.origin.cwiseAbs().maxCoeff() + settings.width + settings.height;
  if (!(farthest <= kMaxCoordinate)) {
    std::ostringstream text;
    text << "grid at origin " << formatVec(settings.origin) << " m, " << settings.width << " m x "
         << settings.height << " m, reaches beyond the " << kMaxCoordinate
         << " m a coordinate may have (kMaxCoordinate); build it near the origin and place it "
            "with ClothSettings::translation";
    return Error{text.str()};
  }
  // Sizes in 64 bits before anything is allocated: the products overflow Index long before.
  const std::uint64_t vertexCount = std::uint64_t(settings.columns) * settings.rows;
  const std::uint64_t triangleCount =
      2 * std::uint64_t(settings.columns - 1) * (settings.rows - 1);
  const std::string size =
      "grid of " + std::to_string(settings.columns) + " x " + std::to_string(settings.rows) + " vertices";
  if (vertexCount >= kInvalidIndex || triangleCount >= kInvalidIndex) {
    return Error{size + " has " + std::to_string(vertexCount) + " vertices and " +
                 std::to_string(triangleCount) + " triangles; a cloth model holds at most " +
                 std::to_string(kInvalidIndex - 1) +
                 " of each (32-bit indices): use fewer columns and rows"};
  }
  if (Status memory = checkMemory(estimatedBuildBytes(vertexCount, triangleCount), size,
                                  "use fewer columns and rows");
      !memory.ok()) {
    return memory.error();
  }

  const Index columns = settings.columns;
  const Index rows = settings.rows;
  const Real spacingU = settings.width / static_cast<Real>(columns - 1);
  const Real spacingV = settings.height / static_cast<Real>(rows - 1);
  auto vertex = [columns](Index row, Index column) { return row * columns + column; };

  TriangleMesh mesh;
  mesh.positions.reserve(std::size_t(rows) * columns);
  mesh.materialCoordinates.reserve(std::size_t(rows) * columns);
  for (Index row = 0; row < rows; ++row) {
    for (Index column = 0; column < columns; ++column) {
      const Real u = spacingU * column;
      const Real v = spacingV * row;
      mesh.positions.push_back(settings.origin + u * widthAxis + v * heightAxis);
      mesh.materialCoordinates.emplace_back(u, v);
    }
  }
  // Each quad is split along its (r, c)–(r+1, c+1) diagonal; both halves wind counter-clockwise
  // in (u, v), so the front faces +widthAxis × heightAxis.
  mesh.indices.reserve(std::size_t(rows - 1) * (columns - 1) * 6);
  for (Index row = 0; row + 1 < rows; ++row) {
    for (Index column = 0; column + 1 < columns; ++column) {
      const Index v00 = vertex(row, column), v01 = vertex(row, column + 1);
      const Index v10 = vertex(row + 1, column), v11 = vertex(row + 1, column + 1);
      mesh.indices.insert(mesh.indices.end(), {v00, v01, v11, v00, v11, v10});
    }
  }

  std::vector<Vec2> perCorner;
  perCorner.reserve(mesh.indices.size());
  for (Index index : mesh.indices) perCorner.push_back(mesh.materialCoordinates[index]);
  Result<ClothModel> built = build(mesh, MeshSettings{}, perCorner, {}, {}, /*meshSprings=*/false);
  if (!built.ok()) return built;
  ClothModel& model = built.value();
  model.m_gridSize = {columns, rows};

  // The classic network (Provot 1995) on the grid's own rows and columns.
  auto addSpring = [&](Index a, Index b, SpringKind kind) {
    model.m_springs.push_back(
        {{a, b}, (model.m_restPositions[a] - model.m_restPositions[b]).norm(), kind});
  };
  for (Index row = 0; row < rows; ++row) {
    for (Index column = 0; column < columns; ++column) {
      const Index here = vertex(row, column);
      if (column + 1 < columns) addSpring(here, vertex(row, column + 1), SpringKind::Structural);
      if (row + 1 < rows) addSpring(here, vertex(row + 1, column), SpringKind::Structural);
    }
  }
  for (Index row = 0; row + 1 < rows; ++row) {
    for (Index column = 0; column + 1 < columns; ++column) {
      addSpring(vertex(row, column), vertex(row + 1, column + 1), SpringKind::Shear);
      addSpring(vertex(row, column + 1), vertex(row + 1, column), SpringKind::Shear);
    }
  }
  for (Index row = 0; row < rows; ++row) {
    for (Index column = 0; column < columns; ++column) {
      const Index here = vertex(row, column);
      if (column + 2 < columns) addSpring(here, vertex(row, column + 2), SpringKind::Flexion);
      if (row + 2 < rows) addSpring(here, vertex(row + 2, column), SpringKind::Flexion);
    }
  }
  return built;
}

Result<ClothModel> ClothModel::fromMesh(const TriangleMesh& mesh, const MeshSettings& settings) {
  if (!settings.warpDirection.allFinite() || settings.warpDirection.norm() == 0) {
    return Error{"MeshSettings::warpDirection " + formatVec(settings.warpDirection) +
                 " must be a finite, non-zero vector"};
  }
  if (!(settings.degenerateAreaRatio >= 0 && settings.degenerateAreaRatio < 0.5)) {
    std::ostringstream text;
    text << "MeshSettings::degenerateAreaRatio = " << settings.degenerateAreaRatio
         << " must be at least 0 and below 0.5 (an equilateral triangle has 0.43)";
    return Error{text.str()};
  }
  if (!(settings.weldTolerance >= 0 && settings.weldTolerance < 1)) {
    std::ostringstream text;
    text << "MeshSettings::weldTolerance = " << settings.weldTolerance
         << " (a fraction of the mesh's bounding-box diagonal) must be at least 0 and below 1; "
            "the default is 1e-6";
    return Error{text.str()};
  }
  if (!mesh.materialCoordinates.empty() &&
      mesh.materialCoordinates.size() != mesh.positions.size()) {
    return Error{"mesh has " + std::to_string(mesh.materialCoordinates.size()) +
                 " material coordinates for " + std::to_string(mesh.positions.size()) +
                 " vertices: give one (u, v) per vertex, or none to flatten each triangle"};
  }
  for (std::size_t i = 0; i < mesh.materialCoordinates.size(); ++i) {
    if (!mesh.materialCoordinates[i].allFinite()) {
      return Error{"material coordinate of vertex " + std::to_string(i) +
                   " is NaN or infinite; give finite (u, v) in metres"};
    }
  }
  const std::string size = "mesh of " + std::to_string(mesh.positions.size()) + " vertices and " +
                           std::to_string(mesh.indices.size() / 3) + " triangles";
  if (Status memory = checkMemory(estimatedBuildBytes(mesh.positions.size(), mesh.indices.size() / 3),
                                  size, "simplify the mesh");
      !memory.ok()) {
    return memory.error();
  }
  Result<PreparedMesh> prepared = prepareMesh(mesh, settings);
  if (!prepared.ok()) return prepared.error();
  PreparedMesh& ready = prepared.value();
  // Per-corner material coordinates: given through a weld, or else from the per-vertex ones or
  // from flattening each triangle on its own (build() does both after its checks).
  Result<ClothModel> model = build(ready.mesh, settings, ready.perCornerMaterialCoordinates,
                                   ready.inputOfModel, ready.bowtieVertices, /*meshSprings=*/true);
  if (!model.ok()) return model;
  model->m_meshImport = std::move(ready.import);
  return model;
}

Result<ClothModel> ClothModel::build(const TriangleMesh& mesh, const MeshSettings& settings,
                                     const std::vector<Vec2>& perCornerMaterialCoordinates,
                                     const std::vector<Index>& inputOfModel,
                                     const std::vector<Index>& bowtieVertices, bool meshSprings) {
  // Shapes, ranges and duplicates were checked by prepareMesh() (or hold by construction for a
  // grid); what is left needs the geometry.
  const std::size_t vertexCount = mesh.positions.size();
  const Index triangleCount = static_cast<Index>(mesh.indices.size() / 3);
  auto input = [&](Index v) { return inputOfModel.empty() ? v : inputOfModel[v]; };
  std::vector<std::uint8_t> used(vertexCount, 0);
  for (Index t = 0; t < triangleCount; ++t) {
    const Index a = mesh.indices[3 * t], b = mesh.indices[3 * t + 1], c = mesh.indices[3 * t + 2];
    const Vec3& x0 = mesh.positions[a];
    const Vec3& x1 = mesh.positions[b];
    const Vec3& x2 = mesh.positions[c];
    const Real twiceArea = (x1 - x0).cross(x2 - x0).norm();
    const Real longestEdge =
        std::max({(x1 - x0).norm(), (x2 - x1).norm(), (x0 - x2).norm()});
    if (!(twiceArea > 2 * settings.degenerateAreaRatio * longestEdge * longestEdge)) {
      std::ostringstream text;
      text << describeTriangle(t, input(a), input(b), input(c)) << ": degenerate, area "
           << 0.5 * twiceArea << " m² for a longest edge of " << longestEdge
           << " m; remove it or move its vertices apart";
      return Error{text.str()};
    }
    used[a] = used[b] = used[c] = 1;
  }
  for (std::size_t i = 0; i < vertexCount; ++i) {
    if (!used[i]) {
      return Error{"vertex " + std::to_string(input(Index(i))) +
                   " is used by no triangle (it would have no mass); remove it from the mesh"};
    }
  }

  ClothModel model;
  model.m_restPositions = mesh.positions;
  model.m_indices = mesh.indices;

  // Rest parameterisation per triangle.
  model.m_triangles.reserve(triangleCount);
  model.m_vertexAreas.assign(vertexCount, 0);
  for (Index t = 0; t < triangleCount; ++t) {
    const std::array<Index, 3> corners{mesh.indices[3 * t], mesh.indices[3 * t + 1],
                                       mesh.indices[3 * t + 2]};
    std::array<Vec2, 3> uv;
    if (!perCornerMaterialCoordinates.empty()) {
      uv = {perCornerMaterialCoordinates[3 * t], perCornerMaterialCoordinates[3 * t + 1],
            perCornerMaterialCoordinates[3 * t + 2]};
    } else if (!mesh.materialCoordinates.empty()) {
      uv = {mesh.materialCoordinates[corners[0]], mesh.materialCoordinates[corners[1]],
            mesh.materialCoordinates[corners[2]]};
    } else {
      uv = flattenTriangle(mesh.positions[corners[0]], mesh.positions[corners[1]],
                           mesh.positions[corners[2]], settings.warpDirection);
    }
    const Real uvTwiceArea =
        std::abs((uv[1] - uv[0]).x() * (uv[2] - uv[0]).y() - (uv[1] - uv[0]).y() * (uv[2] - uv[0]).x());
    const Real uvLongest = std::max({(uv[1] - uv[0]).norm(), (uv[2] - uv[1]).norm(),
                                     (uv[0] - uv[2]).norm()});
    if (!(uvTwiceArea > 2 * settings.degenerateAreaRatio * uvLongest * uvLongest)) {
      return Error{describeTriangle(t, input(corners[0]), input(corners[1]), input(corners[2])) +
                   ": its material coordinates (u, v) are degenerate (zero area); give each "
                   "triangle a non-degenerate (u, v) layout"};
    }
    TriangleRest rest = makeTriangleRest(corners, uv[0], uv[1], uv[2]);
    for (Index corner : corners) model.m_vertexAreas[corner] += rest.area / 3;
    model.m_totalArea += rest.area;
    model.m_triangles.push_back(rest);
  }

  // Edges, in order of first appearance.
  std::unordered_map<std::uint64_t, Index> edgeOfKey;
  edgeOfKey.reserve(std::size_t(triangleCount) * 2);
  for (Index t = 0; t < triangleCount; ++t) {
    for (int k = 0; k < 3; ++k) {
      const Index a = mesh.indices[3 * t + k];
      const Index b = mesh.indices[3 * t + (k + 1) % 3];
      auto [it, inserted] = edgeOfKey.try_emplace(edgeKey(a, b), Index(model.m_edges.size()));
      if (inserted) {
        Edge edge;
        edge.vertices = {std::min(a, b), std::max(a, b)};
        edge.triangles = {t, kInvalidIndex};
        edge.restLength = (mesh.positions[a] - mesh.positions[b]).norm();
        model.m_edges.push_back(edge);
        continue;
      }
      Edge& edge = model.m_edges[it->second];
      if (edge.triangles[1] == kInvalidIndex) {
        edge.triangles[1] = t;
      } else if (settings.requireManifold) {
        return Error{"edge (" + std::to_string(input(edge.vertices[0])) + ", " +
                     std::to_string(input(edge.vertices[1])) + ") is shared by triangles " +
                     std::to_string(edge.triangles[0]) + ", " + std::to_string(edge.triangles[1]) +
                     " and " + std::to_string(t) +
                     ": non-manifold; bending needs at most two triangles per edge (split the "
                     "mesh there, or set MeshSettings::requireManifold = false)"};
      } else {
        edge.triangles[1] = kInvalidIndex - 1;  // marks "more than two": no hinge
      }
    }
  }

  // Hinges on interior manifold edges, oriented by the first triangle's winding.
  for (const Edge& edge : model.m_edges) {
    if (edge.triangles[1] >= kInvalidIndex - 1) continue;
    const Index triangleA = edge.triangles[0];
    const Index triangleB = edge.triangles[1];
    const Index* a = &mesh.indices[3 * triangleA];
    int k = 0;
    while (!((a[k] == edge.vertices[0] || a[k] == edge.vertices[1]) &&
             (a[(k + 1) % 3] == edge.vertices[0] || a[(k + 1) % 3] == edge.vertices[1]))) {
      ++k;
    }
    Hinge hinge;
    hinge.vertices[0] = a[k];
    hinge.vertices[1] = a[(k + 1) % 3];
    hinge.vertices[2] = a[(k + 2) % 3];
    const Index* b = &mesh.indices[3 * triangleB];
    for (int j = 0; j < 3; ++j) {
      if (b[j] != edge.vertices[0] && b[j] != edge.vertices[1]) hinge.vertices[3] = b[j];
    }
    hinge.triangles = {triangleA, triangleB};
    const Vec3Array& x = model.m_restPositions;
    hinge.restAngle = dihedralAngle(x[hinge.vertices[0]], x[hinge.vertices[1]],
                                    x[hinge.vertices[2]], x[hinge.vertices[3]]);
    hinge.restLength = edge.restLength;
    hinge.stiffnessScale = hingeStiffnessScale(edge.restLength, model.m_triangles[triangleA].area,
                                               model.m_triangles[triangleB].area);
    model.m_hinges.push_back(hinge);
  }
  // Isometric bending stencils; they need the non-manifold marks, cleared just below.
  BendingStencils stencils =
      buildBendingStencils(model.m_restPositions, model.m_indices, model.m_edges, bowtieVertices);
  model.m_bendingStencils = std::move(stencils.stencils);
  model.m_bendingWeights = std::move(stencils.weights);
  model.m_bendingTriangles = std::move(stencils.triangles);
  for (Edge& edge : model.m_edges) {
    if (edge.triangles[1] == kInvalidIndex - 1) edge.triangles[1] = kInvalidIndex;
  }

  // Characteristic length: the rest bounding-box diagonal.
  Vec3 lower = mesh.positions[0], upper = mesh.positions[0];
  for (const Vec3& p : mesh.positions) {
    lower = lower.cwiseMin(p);
    upper = upper.cwiseMax(p);
  }
  model.m_characteristicLength = (upper - lower).norm();

  // Mass-spring network for general meshes; grid() replaces it with the classic one.
  if (meshSprings) model.buildMeshSprings();
  return model;
}

void ClothModel::buildMeshSprings() {
  const Vec3Array& x = m_restPositions;
  std::unordered_set<std::uint64_t> connected;
  auto addSpring = [&](Index a, Index b, SpringKind kind) {
    if (!connected.insert(edgeKey(a, b)).second) return;
    m_springs.push_back({{a, b}, (x[a] - x[b]).norm(), kind});
  };
  // Structural: every mesh edge.
  for (const Edge& edge : m_edges) addSpring(edge.vertices[0], edge.vertices[1], SpringKind::Structural);
  // Shear: the other diagonal of the quad formed by the two triangles of an interior edge.
  for (const Hinge& hinge : m_hinges) addSpring(hinge.vertices[2], hinge.vertices[3], SpringKind::Shear);
  // Flexion: skip-one neighbours along nearly straight lines (a–v–b with an angle of at least
  // 150° at v), the mesh analogue of the grid's [i, j]–[i, j+2] springs.
  std::vector<std::vector<Index>> neighbours(x.size());
  for (const Edge& edge : m_edges) {
    neighbours[edge.vertices[0]].push_back(edge.vertices[1]);
    neighbours[edge.vertices[1]].push_back(edge.vertices[0]);
  }
  const Real straightCosine = std::cos(150.0 * 3.14159265358979323846 / 180.0);
  for (Index v = 0; v < x.size(); ++v) {
    const std::vector<Index>& around = neighbours[v];
    for (std::size_t i = 0; i < around.size(); ++i) {
      for (std::size_t j = i + 1; j < around.size(); ++j) {
        const Vec3 toA = (x[around[i]] - x[v]).normalized();
        const Vec3 toB = (x[around[j]] - x[v]).normalized();
        if (toA.dot(toB) <= straightCosine) addSpring(around[i], around[j], SpringKind::Flexion);
      }
    }
  }
}

Result<TriangleMesh> ClothModel::readObj(const std::string& path) {
  Result<std::string> text = readInputFile(path, kMaxObjFileBytes, "OBJ file");
  if (!text.ok()) return text.error();
  // Parsing holds up to 3 bytes per byte of text ("v 0 0 0" is 8 bytes of text, 24 of position).
  if (Status memory = checkMemory(3 * std::uint64_t(text->size()), "reading OBJ file '" + path + "'",
                                  "simplify the mesh");
      !memory.ok()) {
    return memory.error();
  }
  return parseObj(text.value(), "OBJ file '" + path + "'");
}

Result<TriangleMesh> ClothModel::parseObj(std::string_view text, std::string_view source) {
  return parseObjText(text, source);
}

Result<ClothModel> ClothModel::loadObj(const std::string& path, const MeshSettings& settings) {
  Result<TriangleMesh> mesh = readObj(path);
  if (!mesh.ok()) return mesh.error();
  Result<ClothModel> model = fromMesh(mesh.value(), settings);
  // A mesh problem found after reading (degenerate or repeated corners...) names the file too,
  // and how its numbers count.
  if (!model.ok()) {
    return Error{"OBJ file '" + path + "': " + model.error().message +
                 " (vertices and triangles count from 0 here: vertex i is the file's 'v' line "
                 "i + 1, triangle t its t-th triangle after polygons are split)"};
  }
  return model;
}

}  // namespace weft
