// MulticolorOrdering: a colouring of a BlockSparseMatrix's vertex graph, for the multicolour
// symmetric Gauss–Seidel preconditioner of FilteredPcg.
//
// Design note.
// - Why colour. Gauss–Seidel updates vertex i from the newest values of the vertices before it,
//   which is a sequential chain in the natural order. Two vertices that share no block (no force
//   element holds both) never read each other, so a set of pairwise uncoupled vertices (a colour)
//   can be updated in any order, or all at once on many threads, and give the same bits. Sweeping
//   colour after colour is then Gauss–Seidel in the order "colour 0, colour 1, …", vertex order
//   inside a colour, whatever the thread count.
// - How. Greedy colouring in vertex order: each vertex takes the smallest colour none of its
//   already coloured neighbours has. Deterministic (depends only on the pattern), one pass over the
//   stored blocks, and at most (largest row degree + 1) colours. On the cloth grids (1-ring
//   stretch/shear plus the isometric-bending 2-ring) it gives 8–9 colours. Rejected: colourings
//   that balance colour sizes or minimise the count (a few more vertices per colour change nothing
//   at these sizes) and randomised (Jones–Plassmann) colourings, whose result depends on a seed.
// - What is stored. The vertices of each colour, ascending, one colour after another (`order`,
//   `colorOffsets`), and for every row the slots of its blocks split by colour: `lower` slots
//   (column of a smaller colour: the "L" part the forward sweep reads) and `upper` slots (larger
//   colour: the "U" part of the backward sweep). The diagonal is in neither. Slots index the
//   matrix's block array directly, so the sweeps read blocks in place with no copy.
// - The ordering depends on the pattern only, not on the values: build it once per topology
//   (BlockSparseMatrix::patternId() tells when the pattern changed) and reuse it every step.
//   Nothing here depends on how the system is indexed or which vertices it contains.
#pragma once

#include <solver/BlockSparseMatrix.h>

#include <weft/Math.h>

#include <cstdint>
#include <vector>

namespace weft {

/// Colour classes of a block pattern plus the per-row split of its off-diagonal slots.
class MulticolorOrdering {
 public:
  /// Colours `matrix`'s pattern (values are not read). Allocates; call once per pattern.
  void build(const BlockSparseMatrix& matrix);

  /// True when built from a matrix with this pattern id (BlockSparseMatrix::patternId()).
  bool matches(const BlockSparseMatrix& matrix) const {
    return m_patternId == matrix.patternId() && m_patternId != 0;
  }

  /// Number of colours (0 for an empty pattern).
  Index colorCount() const { return static_cast<Index>(m_colorOffsets.size()) - 1; }

  /// Colour of a vertex.
  Index color(Index vertex) const { return m_colors[vertex]; }

  /// Vertices of all colours, colour by colour, ascending within a colour.
  const std::vector<Index>& order() const { return m_order; }

  /// Colour c's vertices are order()[colorBegin(c) … colorEnd(c)).
  Index colorBegin(Index color) const { return m_colorOffsets[color]; }
  Index colorEnd(Index color) const { return m_colorOffsets[color + 1]; }

  /// Slots of row `vertex` whose column has a smaller colour: lowerSlots()[lowerBegin(v) … lowerBegin(v + 1)).
  Index lowerBegin(Index vertex) const { return m_lowerOffsets[vertex]; }
  const std::vector<Index>& lowerSlots() const { return m_lowerSlots; }

  /// Slots of row `vertex` whose column has a larger colour: upperSlots()[upperBegin(v) … upperBegin(v + 1)).
  Index upperBegin(Index vertex) const { return m_upperOffsets[vertex]; }
  const std::vector<Index>& upperSlots() const { return m_upperSlots; }

 private:
  std::uint64_t m_patternId = 0;     ///< pattern this was built from; 0 = never built
  std::vector<Index> m_colors;        ///< colour per vertex
  std::vector<Index> m_order;         ///< vertices sorted by (colour, index)
  std::vector<Index> m_colorOffsets;  ///< colorCount + 1 entries into m_order
  std::vector<Index> m_lowerOffsets;  ///< blockRows + 1 entries into m_lowerSlots
  std::vector<Index> m_lowerSlots;    ///< slots with a smaller-colour column, per row
  std::vector<Index> m_upperOffsets;  ///< blockRows + 1 entries into m_upperSlots
  std::vector<Index> m_upperSlots;    ///< slots with a larger-colour column, per row
};

}  // namespace weft
