// MulticolorOrdering: greedy colouring and the lower/upper slot split. See the header's note.
#include <solver/MulticolorOrdering.h>

#include <algorithm>
#include <cassert>

namespace weft {

namespace {

/// Greedy colouring in vertex order of the graph where neighboursOf(v, visit) calls visit(u) for
/// every neighbour u of v (in any order, repeats allowed). Returns the colour count.
template <typename NeighboursOf>
Index greedyColors(Index vertexCount, NeighboursOf&& neighboursOf, std::vector<Index>& colors) {
  colors.assign(vertexCount, kInvalidIndex);
  // usedBy[c] == vertex marks colour c as taken by a neighbour of vertex.
  std::vector<Index> usedBy;
  Index colorCount = 0;
  for (Index vertex = 0; vertex < vertexCount; ++vertex) {
    neighboursOf(vertex, [&](Index neighbour) {
      if (neighbour < vertex) usedBy[colors[neighbour]] = vertex;
    });
    Index color = 0;
    while (color < colorCount && usedBy[color] == vertex) ++color;
    if (color == colorCount) {
      ++colorCount;
      usedBy.push_back(kInvalidIndex);
    }
    colors[vertex] = color;
  }
  return colorCount;
}

}  // namespace

std::vector<Index> MulticolorOrdering::colorVertices(Index vertexCount,
                                                     std::span<const std::array<Index, 2>> pairs) {
  // Adjacency in CSR form (both directions; duplicates are harmless to the greedy pass).
  std::vector<Index> offsets(static_cast<size_t>(vertexCount) + 1, 0);
  for (const auto& [a, b] : pairs) {
    assert(a < vertexCount && b < vertexCount && "colorVertices: pair index out of range");
    if (a == b) continue;
    ++offsets[a + 1];
    ++offsets[b + 1];
  }
  for (Index v = 0; v < vertexCount; ++v) offsets[v + 1] += offsets[v];
  std::vector<Index> adjacency(offsets.back());
  std::vector<Index> fill(offsets.begin(), offsets.end() - 1);
  for (const auto& [a, b] : pairs) {
    if (a == b) continue;
    adjacency[fill[a]++] = b;
    adjacency[fill[b]++] = a;
  }
  std::vector<Index> colors;
  greedyColors(
      vertexCount,
      [&](Index vertex, auto&& visit) {
        for (Index k = offsets[vertex]; k < offsets[vertex + 1]; ++k) visit(adjacency[k]);
      },
      colors);
  return colors;
}

bool MulticolorOrdering::matches(const BlockSparseMatrix& matrix,
                                 std::span<const Index> rowColors) const {
  return m_patternId != 0 && m_patternId == matrix.patternId() &&
         std::equal(rowColors.begin(), rowColors.end(), m_givenColors.begin(), m_givenColors.end());
}

void MulticolorOrdering::build(const BlockSparseMatrix& matrix, std::span<const Index> rowColors) {
  const Index rows = matrix.blockRows();
  m_givenColors.assign(rowColors.begin(), rowColors.end());

  // The given colours, if they are a colouring of this pattern: one per row, and no coupled pair
  // (no off-diagonal slot) within one colour. Else (none given, or a pattern they do not cover)
  // the greedy colouring of the pattern, which always is.
  m_usesGivenColors = rowColors.size() == rows;
  for (Index row = 0; m_usesGivenColors && row < rows; ++row) {
    for (Index s = matrix.rowBegin(row); s < matrix.rowEnd(row); ++s) {
      const Index column = matrix.column(s);
      if (column != row && rowColors[column] == rowColors[row]) {
        m_usesGivenColors = false;
        break;
      }
    }
  }
  Index colorCount = 0;
  if (m_usesGivenColors) {
    // Keep the given colours' order, dropping colours no row has (held only by removed rows).
    Index largest = 0;
    for (Index color : rowColors) largest = std::max(largest, color);
    std::vector<Index> compact(static_cast<size_t>(largest) + 1, kInvalidIndex);
    for (Index color : rowColors) compact[color] = 0;
    for (Index& slot : compact) {
      if (slot != kInvalidIndex) slot = colorCount++;
    }
    m_colors.resize(rows);
    for (Index row = 0; row < rows; ++row) m_colors[row] = compact[rowColors[row]];
  } else {
    colorCount = greedyColors(
        rows,
        [&](Index vertex, auto&& visit) {
          for (Index s = matrix.rowBegin(vertex); s < matrix.rowEnd(vertex); ++s) {
            visit(matrix.column(s));
          }
        },
        m_colors);
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
  SweepEntries* const lists[] = {&m_lower.general, &m_lower.isotropic, &m_upper.general,
                                 &m_upper.isotropic};
  for (SweepEntries* list : lists) {
    list->offsets.assign(static_cast<size_t>(rows) + 1, 0);
    list->slots.clear();
    list->columns.clear();
  }
  for (Index position = 0; position < rows; ++position) {
    const Index vertex = m_order[position];
    for (Index s = matrix.rowBegin(vertex); s < matrix.rowEnd(vertex); ++s) {
      const Index neighbour = matrix.column(s);
      if (neighbour == vertex) continue;
      SweepTriangle& triangle = m_colors[neighbour] < m_colors[vertex] ? m_lower : m_upper;
      SweepEntries& list = matrix.isotropic(s) ? triangle.isotropic : triangle.general;
      list.slots.push_back(s);
      list.columns.push_back(neighbour);
    }
    for (SweepEntries* list : lists) list->offsets[position + 1] = list->size();
  }
  m_patternId = matrix.patternId();
}

}  // namespace weft
