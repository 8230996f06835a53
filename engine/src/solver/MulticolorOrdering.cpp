// MulticolorOrdering: greedy colouring and the lower/upper slot split. See the header's note.
#include <solver/MulticolorOrdering.h>

#include <algorithm>

namespace weft {

void MulticolorOrdering::build(const BlockSparseMatrix& matrix) {
  const Index rows = matrix.blockRows();
  m_colors.assign(rows, kInvalidIndex);

  // Greedy, vertex order. usedBy[c] == vertex marks colour c as taken by a neighbour of vertex.
  std::vector<Index> usedBy;
  Index colorCount = 0;
  for (Index vertex = 0; vertex < rows; ++vertex) {
    for (Index s = matrix.rowBegin(vertex); s < matrix.rowEnd(vertex); ++s) {
      const Index neighbour = matrix.column(s);
      if (neighbour < vertex) usedBy[m_colors[neighbour]] = vertex;
    }
    Index color = 0;
    while (color < colorCount && usedBy[color] == vertex) ++color;
    if (color == colorCount) {
      ++colorCount;
      usedBy.push_back(kInvalidIndex);
    }
    m_colors[vertex] = color;
  }

  // Counting sort by colour; a stable fill keeps vertices ascending within a colour.
  m_colorOffsets.assign(static_cast<size_t>(colorCount) + 1, 0);
  for (Index vertex = 0; vertex < rows; ++vertex) ++m_colorOffsets[m_colors[vertex] + 1];
  for (Index c = 0; c < colorCount; ++c) m_colorOffsets[c + 1] += m_colorOffsets[c];
  m_order.assign(rows, 0);
  std::vector<Index> fill(m_colorOffsets.begin(), m_colorOffsets.end() - 1);
  for (Index vertex = 0; vertex < rows; ++vertex) m_order[fill[m_colors[vertex]]++] = vertex;

  // Per-row split of the off-diagonal slots. Neighbours never share a colour (that is what the
  // colouring guarantees), so every off-diagonal slot lands in exactly one of the two lists.
  m_lowerOffsets.assign(static_cast<size_t>(rows) + 1, 0);
  m_upperOffsets.assign(static_cast<size_t>(rows) + 1, 0);
  m_lowerSlots.clear();
  m_upperSlots.clear();
  m_lowerSlots.reserve(matrix.blockCount() / 2);
  m_upperSlots.reserve(matrix.blockCount() / 2);
  for (Index vertex = 0; vertex < rows; ++vertex) {
    for (Index s = matrix.rowBegin(vertex); s < matrix.rowEnd(vertex); ++s) {
      const Index neighbour = matrix.column(s);
      if (neighbour == vertex) continue;
      if (m_colors[neighbour] < m_colors[vertex]) m_lowerSlots.push_back(s);
      else m_upperSlots.push_back(s);
    }
    m_lowerOffsets[vertex + 1] = static_cast<Index>(m_lowerSlots.size());
    m_upperOffsets[vertex + 1] = static_cast<Index>(m_upperSlots.size());
  }
  m_patternId = matrix.patternId();
}

}  // namespace weft
