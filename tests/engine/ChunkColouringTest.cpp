// ChunkColouring, the assembly's visiting order: every element once, each colour a run of whole
// chunks of consecutive elements, no two chunks of a colour sharing a vertex, and chunks that
// find every regular colour taken sent to the overflow colour.
#include <forces/ChunkColouring.h>

#include <weft/engine/ClothModel.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

namespace weft {
namespace {

template <std::size_t N>
void expectValidColouring(std::span<const std::array<Index, N>> elements, Index vertexCount,
                          Index chunkSize, const ChunkColouring& colouring) {
  const Index count = Index(elements.size());
  ASSERT_EQ(colouring.order.size(), elements.size());
  ASSERT_GE(colouring.offsets.size(), 2u);
  EXPECT_EQ(colouring.offsets.front(), 0u);
  EXPECT_EQ(colouring.offsets.back(), count);
  std::vector<Index> sorted = colouring.order;
  std::sort(sorted.begin(), sorted.end());
  for (Index e = 0; e < count; ++e) ASSERT_EQ(sorted[e], e) << "element visited other than once";

  for (std::size_t colour = 0; colour + 1 < colouring.offsets.size(); ++colour) {
    const Index first = colouring.offsets[colour], last = colouring.offsets[colour + 1];
    ASSERT_LT(first, last) << "empty colour " << colour;
    std::vector<Index> owner(vertexCount, kInvalidIndex);  // the chunk that holds each vertex
    // A parallelFor block of chunkSize over the colour: one whole chunk, in model order.
    for (Index begin = first; begin < last; begin += chunkSize) {
      const Index end = std::min(begin + chunkSize, last);
      const Index chunk = colouring.order[begin] / chunkSize;
      EXPECT_EQ(colouring.order[begin] % chunkSize, 0u) << "a block does not start a chunk";
      EXPECT_EQ(end - begin, std::min(chunkSize, count - chunk * chunkSize))
          << "a block is not a whole chunk";
      for (Index k = begin; k < end; ++k) {
        ASSERT_EQ(colouring.order[k], colouring.order[begin] + (k - begin))
            << "a chunk's elements are not consecutive";
        if (colour == ChunkColouring::kOverflowColour) continue;
        for (Index vertex : elements[colouring.order[k]]) {
          EXPECT_TRUE(owner[vertex] == kInvalidIndex || owner[vertex] == chunk)
              << "chunks " << owner[vertex] << " and " << chunk << " of colour " << colour
              << " share vertex " << vertex;
          owner[vertex] = chunk;
        }
      }
    }
  }
}

TEST(ChunkColouring, AGridsTrianglesRunAsWholeChunksThatShareNoVertexWithinAColour) {
  GridSettings grid;
  grid.columns = 31;
  grid.rows = 31;
  const ClothModel model = ClothModel::grid(grid).value();
  std::vector<std::array<Index, 3>> triangles;
  for (const TriangleRest& triangle : model.triangles()) triangles.push_back(triangle.vertices);
  for (Index chunkSize : {1u, 7u, 64u, 500u}) {
    SCOPED_TRACE(chunkSize);
    const ChunkColouring colouring = colourChunks(
        std::span<const std::array<Index, 3>>(triangles), model.vertexCount(), chunkSize);
    expectValidColouring(std::span<const std::array<Index, 3>>(triangles), model.vertexCount(),
                         chunkSize, colouring);
  }
}

TEST(ChunkColouring, ShuffledElementsStillShareNoVertexWithinAColour) {
  // Hinges of random vertices: chunks scattered over the mesh, many colours.
  std::mt19937 random(3);
  std::uniform_int_distribution<Index> vertex(0, 399);
  std::vector<std::array<Index, 4>> hinges(900);
  for (auto& hinge : hinges) {
    std::set<Index> distinct;
    while (distinct.size() < 4) distinct.insert(vertex(random));
    std::copy(distinct.begin(), distinct.end(), hinge.begin());
  }
  const ChunkColouring colouring =
      colourChunks(std::span<const std::array<Index, 4>>(hinges), 400, 5);
  expectValidColouring(std::span<const std::array<Index, 4>>(hinges), 400, 5, colouring);
}

TEST(ChunkColouring, ChunksThatFindEveryColourTakenGoToTheOverflowColour) {
  // 70 springs on one hub vertex, one per chunk: each conflicts with all before it, so the first
  // 63 take colours 0 … 62 and the last 7 the overflow colour.
  std::vector<std::array<Index, 2>> springs;
  for (Index k = 0; k < 70; ++k) springs.push_back({0, k + 1});
  const ChunkColouring colouring =
      colourChunks(std::span<const std::array<Index, 2>>(springs), 71, 1);
  ASSERT_EQ(colouring.offsets.size(), std::size_t(ChunkColouring::kOverflowColour) + 2);
  EXPECT_EQ(colouring.offsets[ChunkColouring::kOverflowColour], 63u);
  EXPECT_EQ(colouring.offsets.back(), 70u);
  expectValidColouring(std::span<const std::array<Index, 2>>(springs), 71, 1, colouring);
}

}  // namespace
}  // namespace weft
