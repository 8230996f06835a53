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

  // Split of the off-diagonal slots, in sweep order. Neighbours never share a colour (that is
  // what the colouring guarantees), so every off-diagonal slot lands in exactly one of the lists.
  m_lowerOffsets.assign(static_cast<size_t>(rows) + 1, 0);
  m_upperOffsets.assign(static_cast<size_t>(rows) + 1, 0);
  for (std::vector<Index>* list : {&m_lowerSlots, &m_lowerColumns, &m_upperSlots, &m_upperColumns}) {
    list->clear();
    list->reserve(matrix.blockCount() / 2);
  }
  for (Index position = 0; position < rows; ++position) {
    const Index vertex = m_order[position];
    for (Index s = matrix.rowBegin(vertex); s < matrix.rowEnd(vertex); ++s) {
      const Index neighbour = matrix.column(s);
      if (neighbour == vertex) continue;
      const bool lower = m_colors[neighbour] < m_colors[vertex];
      (lower ? m_lowerSlots : m_upperSlots).push_back(s);
      (lower ? m_lowerColumns : m_upperColumns).push_back(neighbour);
    }
    m_lowerOffsets[position + 1] = static_cast<Index>(m_lowerSlots.size());
    m_upperOffsets[position + 1] = static_cast<Index>(m_upperSlots.size());
  }
  m_patternId = matrix.patternId();
}

}  // namespace weft
