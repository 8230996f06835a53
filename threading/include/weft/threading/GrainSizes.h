// Grain sizes: how many elements one parallelFor block holds, per kind of loop.
//
// Rule: a block carries about 2.5–5 µs of work. That is far more than oneTBB's cost per block and
// more than one warm fork/join (~1.6 µs on the 2-core machine), so scheduling stays in the noise,
// while the curtain still gets several blocks per thread where it has enough work to split.
// Loops whose whole curtain-sized run costs less than a fork/join stay a single block, i.e. run
// inline on the caller with no fork at all. The per-element costs below and the speed-ups they
// give are measured in bench/results/threading-and-bvh.md; remeasure when the kernels change.
#pragma once

#include <weft/threading/TaskSystem.h>

namespace weft {

/// Per-vertex loops (integration, vector updates, PCG axpy/dot over vertices): 2048 × ~2 ns
/// ≈ 4 µs per block. The curtain's 1,271 vertices (~2.5 µs in all, less than a fork/join plus
/// the split imbalance) stay one inline block; ×16 gets 10 blocks.
inline constexpr TaskSystem::Index kGrainVertices = 2048;

/// Per-element force loops (triangles, bending hinges): 64 × ~80 ns ≈ 5 µs per block; the
/// curtain's 2,400 triangles make 38 blocks (19 per thread).
inline constexpr TaskSystem::Index kGrainElements = 64;

/// Per-row loops over the block-sparse matrix (SpMV, preconditioner): 128 × ~20 ns ≈ 2.5 µs
/// per block; the curtain's 1,271 rows make 10 blocks (5 per thread, balanced).
inline constexpr TaskSystem::Index kGrainMatrixRows = 128;

}  // namespace weft
