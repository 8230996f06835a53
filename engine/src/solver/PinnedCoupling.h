// PinnedCoupling: the blocks A(free row, removed vertex) of the implicit system, which carry the
// known velocity change of removed (pinned) vertices to the right-hand side.
//
// Design note.
// With pinned vertices removed (FreeVertexMap.h) the system A Δv = b splits into
//     [A_ff A_fp] [Δv_f]   [b_f]
//     [A_pf A_pp] [Δv_p] = [b_p],   Δv_p known,
// and only A_ff Δv_f = b_f − A_fp Δv_p is solved. A_fp is what this type holds: one 3×3 block
// per (free row, removed vertex) pair that some force element couples, stored by row (CSR over the
// rows that have any, columns increasing). Assembly writes it through precomputed slots exactly as
// it writes the system matrix (every slot has one writer per element), and subtractProduct() sums
// each row's terms in column order, so the right-hand side has the same bits on any thread count.
// For a moving pin Δv_p is nonzero and this term is the pull of the pin on its neighbours; for a
// pin at rest between two frames it vanishes. A_pf and A_pp are never formed.
#pragma once

#include <solver/FreeVertexMap.h>

#include <weft/Math.h>

#include <array>
#include <span>
#include <vector>

namespace weft {

/// The off-diagonal blocks between free rows and removed vertices, A_fp.
class PinnedCoupling {
 public:
  /// Builds the pattern from the coupled vertex pairs of the model (either order, duplicates
  /// allowed): a block for each pair of one free and one removed vertex. Allocates; set-up only.
  void build(const FreeVertexMap& map, std::span<const std::array<Index, 2>> coupledPairs);

  /// Number of stored blocks.
  Index blockCount() const { return static_cast<Index>(m_blocks.size()); }
  /// Slot of block (row, removed vertex), or kInvalidIndex when they are not coupled. Binary
  /// search: meant for set-up time.
  Index slot(Index row, Index removedVertex) const;
  /// The block at a slot from slot().
  Mat3& block(Index slot) { return m_blocks[slot]; }
  const Mat3& block(Index slot) const { return m_blocks[slot]; }
  /// Zeroes every block, keeping the pattern (the start of each assembly).
  void setZero();

  /// rows[r] −= Σ_p A(r, p) vertexDeltaV[p] over the stored blocks, each row's terms in
  /// increasing p (fixed order). vertexDeltaV is indexed by vertex, rows by row.
  void subtractProduct(const Vec3Array& vertexDeltaV, Vec3Array& rows) const;

 private:
  std::vector<Index> m_rows;         // rows with at least one block, increasing
  std::vector<Index> m_offsets;      // m_rows.size() + 1; row m_rows[k] owns [m_offsets[k], m_offsets[k + 1])
  std::vector<Index> m_columns;      // removed vertex per slot, increasing within a row
  std::vector<Mat3> m_blocks;        // one per slot
};

}  // namespace weft
