// PinnedCoupling: see the design note in the header.
#include <solver/PinnedCoupling.h>

#include <algorithm>

namespace weft {

void PinnedCoupling::build(const FreeVertexMap& map,
                           std::span<const std::array<Index, 2>> coupledPairs) {
  // (row, removed vertex) entries, sorted and made unique: the CSR pattern in one pass.
  std::vector<std::array<Index, 2>> entries;
  for (const auto& [a, b] : coupledPairs) {
    if (a >= map.vertexCount() || b >= map.vertexCount()) continue;
    const Index rowA = map.row(a), rowB = map.row(b);
    if (rowA != kInvalidIndex && rowB == kInvalidIndex) entries.push_back({rowA, b});
    if (rowB != kInvalidIndex && rowA == kInvalidIndex) entries.push_back({rowB, a});
  }
  std::sort(entries.begin(), entries.end());
  entries.erase(std::unique(entries.begin(), entries.end()), entries.end());

  m_rows.clear();
  m_offsets.clear();
  m_columns.clear();
  for (const auto& [row, column] : entries) {
    if (m_rows.empty() || m_rows.back() != row) {
      m_rows.push_back(row);
      m_offsets.push_back(static_cast<Index>(m_columns.size()));
    }
    m_columns.push_back(column);
  }
  m_offsets.push_back(static_cast<Index>(m_columns.size()));
  m_blocks.assign(m_columns.size(), Mat3::Zero());
}

Index PinnedCoupling::slot(Index row, Index removedVertex) const {
  const auto rowIt = std::lower_bound(m_rows.begin(), m_rows.end(), row);
  if (rowIt == m_rows.end() || *rowIt != row) return kInvalidIndex;
  const std::size_t k = static_cast<std::size_t>(rowIt - m_rows.begin());
  const auto first = m_columns.begin() + m_offsets[k];
  const auto last = m_columns.begin() + m_offsets[k + 1];
  const auto it = std::lower_bound(first, last, removedVertex);
  if (it == last || *it != removedVertex) return kInvalidIndex;
  return static_cast<Index>(it - m_columns.begin());
}

void PinnedCoupling::setZero() {
  for (Mat3& block : m_blocks) block.setZero();
}

void PinnedCoupling::subtractProduct(const Vec3Array& vertexDeltaV, Vec3Array& rows) const {
  for (std::size_t k = 0; k < m_rows.size(); ++k) {
    Vec3 sum = Vec3::Zero();
    for (Index s = m_offsets[k]; s < m_offsets[k + 1]; ++s) {
      sum.noalias() += m_blocks[s] * vertexDeltaV[m_columns[s]];
    }
    rows[m_rows[k]] -= sum;
  }
}

}  // namespace weft
