// MeshPreparation: a triangle mesh as content tools export it → one ClothModel::build() can take.
//
// Design note
// -----------
// Three passes, each in the order of the input so that the same mesh always gives the same model:
//
// 1. Checks in the caller's numbering: sizes within the 32-bit index range, finite positions
//    within kMaxCoordinate, indices in range, three distinct corners per triangle.
// 2. Welding (MeshSettings::weldVertices): vertices within weldTolerance × the bounding-box
//    diagonal of an earlier kept vertex join it (a hash grid of cells one tolerance wide, the 27
//    cells around each vertex searched, the lowest-numbered kept vertex in reach wins). Chains
//    are not followed: a vertex joins a kept vertex in reach, never one already merged, so the
//    result does not depend on a cell's contents beyond the tolerance. Kept vertices are
//    renumbered in input order. A weld that puts two corners of one triangle together is an
//    error: the tolerance is then larger than that triangle.
// 3. Orientation (MeshSettings::fixWinding): edges are found by sorting half-edges; two
//    triangles across a manifold edge agree when they run it in opposite directions. A breadth-
//    first walk from the lowest-numbered triangle of each connected piece flips every triangle
//    that disagrees with the one it was reached from; reaching a triangle already placed the
//    other way proves the piece non-orientable (a Möbius strip), reported with both triangles
//    and the edge. Bowtie vertices are found on the same edges: the triangles around a vertex
//    joined through manifold edges form its fans; more than one fan is a bowtie (an error, or
//    without requireManifold a vertex that gets no bending stencil).
//
// Rejected: welding by exact position only (exporters write the same vertex with different
// rounding in different groups), and orienting by normals (a folded garment's neighbours may
// face opposite ways in space while agreeing in winding).
#pragma once

#include <weft/engine/ClothModel.h>

#include <vector>

namespace weft {

/// A mesh ready for ClothModel::build(): welded, oriented and checked.
struct PreparedMesh {
  TriangleMesh mesh;  ///< welded positions, oriented triangles, per-vertex uv when kept
  /// Three (u, v) per triangle when the input's per-vertex coordinates could not be kept (a weld
  /// merged vertices with different coordinates); empty otherwise.
  std::vector<Vec2> perCornerMaterialCoordinates;
  std::vector<Index> inputOfModel;  ///< input vertex of each model vertex; empty: the same
  /// Bowtie vertices, ascending (model numbering), when MeshSettings::requireManifold is off.
  std::vector<Index> bowtieVertices;
  MeshImport import;                ///< what changed, for the caller
};

/// Checks, welds and orients `mesh` (see the design note). Errors name input vertices and
/// triangles.
Result<PreparedMesh> prepareMesh(const TriangleMesh& mesh, const MeshSettings& settings);

}  // namespace weft
