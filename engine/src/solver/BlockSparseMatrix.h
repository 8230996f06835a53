// BlockSparseMatrix: the symmetric 3×3-block matrix of the implicit step,
// A = M − h ∂f/∂v − h² ∂f/∂x (Baraff & Witkin 1998, §4.2 and eq. 18).
//
// Design note.
// - The sparsity is fixed by the mesh topology: two vertices are coupled when some force element
//   (triangle, hinge, spring) holds both. So the pattern is built once from the coupled pairs and
//   every step only overwrites block values. Each element precomputes, at set-up time, the slot
//   of every block it writes (slot(row, col)); assembly then writes through those indices with no
//   search, no allocation and no lock, since every slot has exactly one writer per element.
// - Full rows are stored, both (i, j) and (j, i), CSR-style: row offsets, column indices sorted
//   within each row, one Mat3 per stored block. Storing only the upper triangle would halve the
//   memory but turn SpMV into a scatter (row i also adds into y[j]), which needs atomics or
//   per-thread copies to run in parallel and changes the summation order with the thread count.
//   With full rows SpMV is a per-row gather: each y[i] is summed by one thread in column order,
//   so any split of the rows gives the same bits (multiplyRows is that split).
// - Isotropic blocks. A block that every writer keeps a multiple of the identity (isometric
//   bending's K̂_ij I₃ between vertices no membrane element shares: 12 of a grid row's 18
//   off-diagonal blocks) is marked at build time (isotropic()). Storage stays one Mat3 a slot, so
//   assembly and SpMV do not care; the Gauss–Seidel sweeps pack such a block as one scalar, a
//   ninth of its bytes and a third of its multiplies.
// - Rejected: Eigen::SparseMatrix<Real> of scalars (9× the index traffic, no 3×3 block kernels,
//   and insertions that may allocate), and a hash map from (i, j) to a block (slow lookups in the
//   assembly loop; slots make lookup a set-up cost).
#pragma once

#include <weft/Math.h>

#include <Eigen/SparseCore>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace weft {

/// Symmetric block-sparse matrix of Mat3 blocks with a pattern fixed at build time.
class BlockSparseMatrix {
 public:
  /// An empty matrix (no rows); call build() before use.
  BlockSparseMatrix() = default;

  /// Same as build(blockRows, coupledPairs, isotropicPairs).
  BlockSparseMatrix(Index blockRows, std::span<const std::array<Index, 2>> coupledPairs,
                    std::span<const std::array<Index, 2>> isotropicPairs = {});

  /// Builds the pattern: blockRows diagonal blocks plus blocks (i, j) and (j, i) for every pair.
  /// Duplicate pairs (in either order) are merged; a pair (i, i) names the diagonal, which is
  /// always present. Every index must be < blockRows (asserted; skipped in release builds).
  /// isotropicPairs: pairs of coupledPairs whose two blocks the caller promises to keep multiples
  /// of the identity (isotropic()); pairs not in coupledPairs and diagonal pairs are ignored.
  /// All blocks start at zero. Allocates; call at set-up time only.
  void build(Index blockRows, std::span<const std::array<Index, 2>> coupledPairs,
             std::span<const std::array<Index, 2>> isotropicPairs = {});

  /// Identifies the pattern: a fresh nonzero value at every build(), kept by copies, 0 before the
  /// first build. Lets pattern-dependent caches (MulticolorOrdering) know when to rebuild.
  std::uint64_t patternId() const { return m_patternId; }

  /// Number of block rows (= block columns = vertices).
  Index blockRows() const { return static_cast<Index>(m_diagonalSlots.size()); }

  /// Number of stored blocks, counting (i, j) and (j, i) separately and the diagonal once.
  Index blockCount() const { return static_cast<Index>(m_blocks.size()); }

  /// Slot of block (row, col), or kInvalidIndex when the pair is not coupled. Binary search:
  /// meant for set-up time, where elements precompute the slots they write.
  Index slot(Index row, Index col) const;

  /// Slot of the diagonal block (row, row); O(1).
  Index diagonalSlot(Index row) const { return m_diagonalSlots[row]; }

  /// The block stored at a slot from slot() or diagonalSlot().
  Mat3& block(Index slot) { return m_blocks[slot]; }

  /// The block stored at a slot from slot() or diagonalSlot().
  const Mat3& block(Index slot) const { return m_blocks[slot]; }

  /// True when the block at an off-diagonal slot is a multiple of the identity by construction
  /// (build()'s isotropicPairs); its value is then block(slot)(0, 0) times I₃.
  bool isotropic(Index slot) const { return m_isotropic[slot] != 0; }

  /// Sets every stored block to zero, keeping the pattern (the start of each assembly).
  void setZero();

  /// First slot of a row; the row's slots are [rowBegin(row), rowEnd(row)), columns ascending.
  Index rowBegin(Index row) const { return m_rowOffsets[row]; }

  /// One past the last slot of a row.
  Index rowEnd(Index row) const { return m_rowOffsets[row + 1]; }

  /// Block column of a slot.
  Index column(Index slot) const { return m_columns[slot]; }

  /// (A x)_row = Σ_col A(row, col) x[col], summed in ascending column order (fixed, so the same
  /// bits whichever thread computes the row).
  Vec3 multiplyRow(Index row, const Vec3Array& x) const {
    Vec3 sum = Vec3::Zero();
    for (Index s = m_rowOffsets[row], end = m_rowOffsets[row + 1]; s < end; ++s) {
      sum.noalias() += m_blocks[s] * x[m_columns[s]];
    }
    return sum;
  }

  /// y = A x. x and y must have blockRows() entries and must not alias.
  void multiply(const Vec3Array& x, Vec3Array& y) const;

  /// y[row] = (A x)_row for row in [begin, end), other rows of y untouched. Splitting the rows
  /// over threads gives results bitwise identical to multiply(). x and y must not alias.
  void multiplyRows(Index begin, Index end, const Vec3Array& x, Vec3Array& y) const;

  /// The same matrix as a scalar (3n × 3n) Eigen sparse matrix, explicit zeros kept; for tests
  /// and debugging (allocates).
  Eigen::SparseMatrix<Real> toEigen() const;

 private:
  std::vector<Index> m_rowOffsets;     ///< blockRows + 1 entries; row r owns [m_rowOffsets[r], m_rowOffsets[r + 1])
  std::vector<Index> m_columns;        ///< block column per slot, ascending within a row
  std::vector<Index> m_diagonalSlots;  ///< slot of (r, r) per row
  std::vector<Mat3> m_blocks;          ///< one block per slot
  std::vector<std::uint8_t> m_isotropic;  ///< 1 on the slots of isotropic() blocks
  std::uint64_t m_patternId = 0;       ///< see patternId()
};

}  // namespace weft
