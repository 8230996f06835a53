// sortTrianglePairs: the ordering step of the broad-phase queries, in linear time.
//
// A self query on the ×16 curtain returns ~10⁵ pairs; std::sort on them cost as much as the tree
// traversal itself (≈3 ms of ≈8 ms). Pairs of indices below a known bound are integers of at most
// 2·⌈log2 bound⌉ bits, so an LSD radix sort (digits of up to 12 bits: 3 passes for meshes up to
// 2¹⁸ triangles, 4 up to 2²⁴) orders them in O(n). The scatter buffer is the upper half of the
// caller's own vector (resized to twice the count, then back), so a vector reused from frame to
// frame stops allocating once its capacity has grown: no hidden state in the tree, and queries
// on one tree from several threads stay safe.
#pragma once

#include <weft/collision/Bvh.h>

#include <vector>

namespace weft::detail {

/// Sorts `pairs` by (first, second); every index must be below `indexBound`. Stable, O(n).
void sortTrianglePairs(std::vector<TrianglePair>& pairs, Index indexBound);

}  // namespace weft::detail
