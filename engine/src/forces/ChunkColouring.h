// ChunkColouring: the order in which the assembly visits elements so that threads never write the
// same force entry or matrix block, and each thread writes memory that lies close together.
//
// Elements (triangles, hinges, springs) are cut into chunks of `chunkSize` consecutive elements in
// model order, which keeps a chunk's vertices, and so the matrix rows it writes, near each other.
// The chunks are coloured greedily in order: each takes the lowest colour that no chunk sharing one
// of its vertices has taken. Visiting the elements by colour (stably) makes every colour a run of
// whole chunks, with the one short chunk, the last, at the end of its colour; so a parallelFor
// block of `chunkSize` over a colour is exactly one chunk. A chunk runs in order on one thread, and
// chunks of one colour share no vertex: no locks, no atomics, and every entry receives its
// contributions in an order fixed by the model alone.
// Rejected: colouring single elements. A regular grid's triangles then need 6 colours, and each
// colour sweeps the whole matrix in scattered order; on a 38,400-triangle cloth the assembly takes
// about twice as long, its block writes missing the caches.
#pragma once

#include <weft/Math.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace weft {

/// Where each element goes in the visiting order, and where each colour's run starts.
struct ChunkColouring {
  std::vector<Index> order;    ///< element indices (model order) in visiting order
  std::vector<Index> offsets;  ///< colour k visits order[offsets[k], offsets[k + 1])
  /// Colours are tracked in a 64-bit mask per vertex; chunks that find all 63 regular colours
  /// taken go to this last colour, whose chunks may share vertices: run it as one serial block.
  static constexpr Index kOverflowColour = 63;
};

/// Colours the chunks of `elements` (each an array of vertex indices below `vertexCount`).
template <std::size_t N>
ChunkColouring colourChunks(std::span<const std::array<Index, N>> elements, Index vertexCount,
                            Index chunkSize) {
  std::vector<std::uint64_t> usedColours(vertexCount, 0);  // bit k: the vertex has colour k
  const Index count = Index(elements.size());
  const Index chunkCount = (count + chunkSize - 1) / chunkSize;
  std::vector<Index> colourOfChunk(chunkCount);
  Index colourCount = 0;
  for (Index chunk = 0; chunk < chunkCount; ++chunk) {
    const Index begin = chunk * chunkSize, end = std::min(begin + chunkSize, count);
    std::uint64_t taken = 0;
    for (Index e = begin; e < end; ++e) {
      for (Index vertex : elements[e]) taken |= usedColours[vertex];
    }
    Index colour = 0;
    while (colour < ChunkColouring::kOverflowColour && (taken >> colour & 1u)) ++colour;
    colourOfChunk[chunk] = colour;
    for (Index e = begin; e < end; ++e) {
      for (Index vertex : elements[e]) usedColours[vertex] |= std::uint64_t(1) << colour;
    }
    colourCount = std::max(colourCount, colour + 1);
  }
  ChunkColouring colouring;
  colouring.order.resize(count);
  for (Index e = 0; e < count; ++e) colouring.order[e] = e;
  const auto colourOf = [&](Index e) { return colourOfChunk[e / chunkSize]; };
  std::stable_sort(colouring.order.begin(), colouring.order.end(),
                   [&](Index a, Index b) { return colourOf(a) < colourOf(b); });
  colouring.offsets.assign(colourCount + 1, 0);
  for (Index e = 0; e < count; ++e) ++colouring.offsets[colourOf(e) + 1];
  for (Index k = 0; k < colourCount; ++k) colouring.offsets[k + 1] += colouring.offsets[k];
  return colouring;
}

}  // namespace weft
