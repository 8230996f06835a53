// BlockSparseMatrix: pattern build, lookup and products. See the design note in the header.
#include <solver/BlockSparseMatrix.h>

#include <algorithm>
#include <atomic>
#include <cassert>

namespace weft {

BlockSparseMatrix::BlockSparseMatrix(Index blockRows,
                                     std::span<const std::array<Index, 2>> coupledPairs,
                                     std::span<const std::array<Index, 2>> isotropicPairs) {
  build(blockRows, coupledPairs, isotropicPairs);
}

void BlockSparseMatrix::build(Index blockRows,
                              std::span<const std::array<Index, 2>> coupledPairs,
                              std::span<const std::array<Index, 2>> isotropicPairs) {
  // Counting sort by row: first the number of candidate entries per row (diagonal + every
  // occurrence of the row in a pair, duplicates included), then fill, then sort and merge each row.
  std::vector<Index> candidateOffsets(static_cast<size_t>(blockRows) + 1, 0);
  for (Index row = 0; row < blockRows; ++row) candidateOffsets[row + 1] = 1;
  for (const auto& [i, j] : coupledPairs) {
    assert(i < blockRows && j < blockRows &&
           "BlockSparseMatrix::build: pair index out of range; pass the vertex count as blockRows");
    if (i >= blockRows || j >= blockRows || i == j) continue;
    ++candidateOffsets[i + 1];
    ++candidateOffsets[j + 1];
  }
  for (Index row = 0; row < blockRows; ++row) candidateOffsets[row + 1] += candidateOffsets[row];

  std::vector<Index> candidates(candidateOffsets[blockRows]);
  std::vector<Index> fill(candidateOffsets.begin(), candidateOffsets.end() - 1);
  for (Index row = 0; row < blockRows; ++row) candidates[fill[row]++] = row;
  for (const auto& [i, j] : coupledPairs) {
    if (i >= blockRows || j >= blockRows || i == j) continue;
    candidates[fill[i]++] = j;
    candidates[fill[j]++] = i;
  }

  // Sorted, duplicate-free columns per row, compacted into the final arrays.
  m_rowOffsets.assign(static_cast<size_t>(blockRows) + 1, 0);
  m_columns.clear();
  m_columns.reserve(candidates.size());
  m_diagonalSlots.assign(blockRows, kInvalidIndex);
  for (Index row = 0; row < blockRows; ++row) {
    auto first = candidates.begin() + candidateOffsets[row];
    auto last = candidates.begin() + candidateOffsets[row + 1];
    std::sort(first, last);
    last = std::unique(first, last);
    for (auto it = first; it != last; ++it) {
      if (*it == row) m_diagonalSlots[row] = static_cast<Index>(m_columns.size());
      m_columns.push_back(*it);
    }
    m_rowOffsets[row + 1] = static_cast<Index>(m_columns.size());
  }
  m_columns.shrink_to_fit();
  m_blocks.assign(m_columns.size(), Mat3::Zero());
  m_isotropic.assign(m_columns.size(), 0);
  for (const auto& [i, j] : isotropicPairs) {
    if (i == j) continue;
    for (const Index s : {slot(i, j), slot(j, i)}) {
      if (s != kInvalidIndex) m_isotropic[s] = 1;
    }
  }
  // Unique across all matrices of the process, so a cache keyed on it cannot mistake a new
  // matrix (perhaps at the address of an old one) for the pattern it was built from.
  static std::atomic<std::uint64_t> nextPatternId{1};
  m_patternId = nextPatternId.fetch_add(1, std::memory_order_relaxed);
}

Index BlockSparseMatrix::slot(Index row, Index col) const {
  if (row >= blockRows() || col >= blockRows()) return kInvalidIndex;
  const auto first = m_columns.begin() + m_rowOffsets[row];
  const auto last = m_columns.begin() + m_rowOffsets[row + 1];
  const auto it = std::lower_bound(first, last, col);
  if (it == last || *it != col) return kInvalidIndex;
  return static_cast<Index>(it - m_columns.begin());
}

void BlockSparseMatrix::setZero() {
  for (Mat3& b : m_blocks) b.setZero();
}

void BlockSparseMatrix::multiply(const Vec3Array& x, Vec3Array& y) const {
  multiplyRows(0, blockRows(), x, y);
}

void BlockSparseMatrix::multiplyRows(Index begin, Index end, const Vec3Array& x,
                                     Vec3Array& y) const {
  assert(x.size() == blockRows() && y.size() == blockRows() &&
         "BlockSparseMatrix::multiplyRows: x and y need blockRows() entries");
  assert(&x != &y && "BlockSparseMatrix::multiplyRows: x and y must be different arrays");
  for (Index row = begin; row < end; ++row) y[row] = multiplyRow(row, x);
}

Eigen::SparseMatrix<Real> BlockSparseMatrix::toEigen() const {
  std::vector<Eigen::Triplet<Real>> triplets;
  triplets.reserve(m_blocks.size() * 9);
  for (Index row = 0; row < blockRows(); ++row) {
    for (Index s = rowBegin(row); s < rowEnd(row); ++s) {
      const Index col = m_columns[s];
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          triplets.emplace_back(3 * row + a, 3 * col + b, m_blocks[s](a, b));
        }
      }
    }
  }
  const Eigen::Index size = 3 * static_cast<Eigen::Index>(blockRows());
  Eigen::SparseMatrix<Real> result(size, size);
  result.setFromTriplets(triplets.begin(), triplets.end());
  return result;
}

}  // namespace weft
