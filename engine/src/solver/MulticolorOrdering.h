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
//   already coloured neighbours has. Deterministic (depends only on the graph), one pass over the
//   pairs, and at most (largest degree + 1) colours. On the cloth grids (1-ring stretch/shear plus
//   the isometric-bending 2-ring) it gives 8–9 colours. Rejected: colourings that balance colour
//   sizes or minimise the count (a few more vertices per colour change nothing at these sizes)
//   and randomised (Jones–Plassmann) colourings, whose result depends on a seed.
// - Which graph. The order changes the preconditioner, so the iterates, so the bits of the
//   answer (within the solve tolerance). Colouring the assembled pattern would make the answer
//   depend on which force terms are structurally present (a cloth that skips its zero bending
//   assembles no 2-ring: fewer colours, another order) and on which vertices are rows (removing
//   pins renumbers and prunes the graph). So the owner of the system colours its vertices once,
//   from every pair its force terms could couple whatever their coefficients (colorVertices), and
//   passes the colours of its rows (`rowColors`): a cloth then sweeps in the same order with or
//   without zero terms, with pins removed or filtered, and the skipped or removed couplings are
//   exactly the zero blocks they would have been. A colouring that does not separate every
//   coupled pair of the pattern (or none given: tests, other systems) falls back to colouring the
//   pattern itself, so the sweeps are always correct; usesGivenColors() tells which was used.
//   Colours no row has (say, held only by removed pins) are dropped, keeping their order.
// - What is stored. The vertices of each colour, ascending, one colour after another (`order`,
//   `colorOffsets`), and for every row the slots of its blocks split by colour: `lower` slots
//   (column of a smaller colour: the "L" part the forward sweep reads) and `upper` slots (larger
//   colour: the "U" part of the backward sweep), listed in sweep order with their columns, and
//   each split again into general blocks and isotropic ones (BlockSparseMatrix::isotropic()),
//   which the sweeps store and multiply as scalars. The diagonal is in none. FilteredPcg copies
//   the blocks of these slots once per solve into arrays in the same order, so every sweep streams
//   through memory front to back.
// - The ordering depends on the pattern and the given colours only, not on the values: build it
//   once per topology (BlockSparseMatrix::patternId() tells when the pattern changed) and reuse it
//   every step.
#pragma once

#include <solver/BlockSparseMatrix.h>

#include <weft/Math.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace weft {

/// Off-diagonal entries in sweep order: position k (vertex order()[k]) owns entries
/// [begin(k), begin(k + 1)); entry e names the matrix slot (slots[e]) and the column vertex
/// (columns[e]), so a sweep reads both arrays front to back.
struct SweepEntries {
  std::vector<Index> offsets;  ///< blockRows + 1 entries (per sweep position) into slots/columns
  std::vector<Index> slots;    ///< matrix slot per entry
  std::vector<Index> columns;  ///< column vertex per entry
  Index begin(Index position) const { return offsets[position]; }
  Index size() const { return static_cast<Index>(slots.size()); }
};

/// One triangle of the off-diagonal part (lower or upper), its general and isotropic blocks apart.
struct SweepTriangle {
  SweepEntries general;    ///< blocks stored as Mat3
  SweepEntries isotropic;  ///< blocks that are multiples of the identity (stored as a scalar)
};

/// Colour classes of a block pattern plus the per-row split of its off-diagonal slots.
class MulticolorOrdering {
 public:
  /// Greedy colouring, in vertex order, of the graph on vertexCount vertices whose edges are
  /// `pairs` (duplicates and (i, i) allowed; every index < vertexCount). Coupled vertices get
  /// different colours. Allocates; for set-up time.
  static std::vector<Index> colorVertices(Index vertexCount,
                                          std::span<const std::array<Index, 2>> pairs);

  /// Orders `matrix`'s rows (values are not read): by rowColors (one colour per row, e.g. from
  /// colorVertices() on a supergraph of the pattern) when they separate every coupled pair of
  /// the pattern, else by a greedy colouring of the pattern itself. Allocates; once per pattern.
  void build(const BlockSparseMatrix& matrix, std::span<const Index> rowColors = {});

  /// True when built from a matrix with this pattern id (BlockSparseMatrix::patternId()) and
  /// these row colours (compared entry by entry: O(rows), no allocation).
  bool matches(const BlockSparseMatrix& matrix, std::span<const Index> rowColors = {}) const;

  /// True when the last build() used the given row colours (false: it coloured the pattern).
  bool usesGivenColors() const { return m_usesGivenColors; }

  /// Number of colours (0 for an empty pattern).
  Index colorCount() const { return static_cast<Index>(m_colorOffsets.size()) - 1; }

  /// Colour of a vertex.
  Index color(Index vertex) const { return m_colors[vertex]; }

  /// Vertices of all colours, colour by colour, ascending within a colour.
  const std::vector<Index>& order() const { return m_order; }

  /// Colour c's vertices are order()[colorBegin(c) … colorEnd(c)).
  Index colorBegin(Index color) const { return m_colorOffsets[color]; }
  Index colorEnd(Index color) const { return m_colorOffsets[color + 1]; }

  /// Entries whose column has a smaller colour (the forward sweep's L̃), in sweep order.
  const SweepTriangle& lower() const { return m_lower; }
  /// Entries whose column has a larger colour (the backward sweep's Ũ), in sweep order.
  const SweepTriangle& upper() const { return m_upper; }

 private:
  std::uint64_t m_patternId = 0;     ///< pattern this was built from; 0 = never built
  std::vector<Index> m_givenColors;   ///< rowColors of the last build(), as given
  bool m_usesGivenColors = false;     ///< m_colors are m_givenColors (compacted), not greedy
  std::vector<Index> m_colors;        ///< colour per vertex
  std::vector<Index> m_order;         ///< vertices sorted by (colour, index)
  std::vector<Index> m_colorOffsets;  ///< colorCount + 1 entries into m_order
  SweepTriangle m_lower;               ///< slots with a smaller-colour column, in sweep order
  SweepTriangle m_upper;               ///< slots with a larger-colour column, in sweep order
};

}  // namespace weft
