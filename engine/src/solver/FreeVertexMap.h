// FreeVertexMap: which vertices are unknowns of the implicit solve, and their row numbers.
//
// Design note.
// A pinned vertex's velocity change is known before the solve (it lands on its target), so it is
// not an unknown. BW98 §5.3 keep such vertices in the system and filter them (S = 0): every PCG
// sweep still walks their rows and they cost as much as free vertices. Here they are removed
// instead: the system's rows are the free vertices only, numbered in increasing vertex order (so a
// row range is a vertex range, and reductions over rows keep a fixed order), and each free row's
// coupling to a removed vertex moves to the right-hand side (PinnedCoupling.h):
//     A_ff Δv_f = b_f − A_fp Δv_p.
// Contacts stay in the filter: they change every step, and renumbering the rows per step would
// rebuild the matrix pattern per step. The map is built when the pin set is (set-up time); the
// step only reads it, so nothing allocates. A map that removes nothing is the identity (every
// vertex is its own row), which keeps the filtered path of the old code for checks and tests.
#pragma once

#include <weft/Math.h>

#include <span>
#include <vector>

namespace weft {

/// Vertex ↔ row numbering of the implicit system with some vertices removed.
class FreeVertexMap {
 public:
  /// Builds the map for vertexCount vertices with `removed` (increasing, < vertexCount) taken out
  /// of the system. Allocates: call when the pin set changes, never per step.
  void build(Index vertexCount, std::span<const Index> removed);

  /// Number of vertices of the cloth.
  Index vertexCount() const { return static_cast<Index>(m_rowOfVertex.size()); }
  /// Number of rows of the system (free vertices).
  Index rowCount() const { return static_cast<Index>(m_vertexOfRow.size()); }
  /// Row of a vertex, or kInvalidIndex for a removed vertex.
  Index row(Index vertex) const { return m_rowOfVertex[vertex]; }
  /// Vertex of a row.
  Index vertex(Index row) const { return m_vertexOfRow[row]; }
  /// True when no vertex is removed (row i is vertex i).
  bool isIdentity() const { return rowCount() == vertexCount(); }

  /// rows[r] = vertices[vertex(r)] for every row; rows must have rowCount() entries.
  void gather(const Vec3Array& vertices, Vec3Array& rows) const;
  /// vertices[vertex(r)] = rows[r] for every row; removed vertices' entries are left untouched.
  void scatter(const Vec3Array& rows, Vec3Array& vertices) const;

 private:
  std::vector<Index> m_rowOfVertex;  // kInvalidIndex for removed vertices
  std::vector<Index> m_vertexOfRow;  // increasing
};

}  // namespace weft
