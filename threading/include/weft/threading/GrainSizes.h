// Grain sizes: how many elements one parallelFor block holds, per kind of loop.
//
// Rule: a block should carry about 2.5–5 µs of work. That is ≥ 100× what oneTBB charges per
// block and above one warm fork/join (both measured below), so scheduling stays in the noise,
// while the curtain (the scene the 1 ms budget is about) still gets several blocks per thread
// where it has enough work to split.
// Loops whose whole curtain-sized run costs less than a fork/join stay a single block, i.e. run
// inline on the caller with no fork at all.
//
// Measured on the 2-core development machine (Debian bookworm, oneTBB 2021.8, -O3, TaskSystem
// with 2 threads) by a throwaway program timing TaskSystem::parallelFor with FrameClock::nowNs();
// medians of two runs started when both cores had been ≥ 85 % idle for 3 s:
//   * empty parallelFor of 2 blocks, back to back ............ 0.14 µs (the caller runs both);
//     after 5 ms idle 1.7–3.4 µs (90th percentile 13–17 µs)
//   * 2 blocks × 20 µs of spinning, back to back: wall − 20 µs  1.6 µs  = warm fork/join
//   * the same after 5 ms idle (workers asleep) ............... 22–33 µs: the worker wakes so
//     late that the caller runs both blocks. The first parallel loop of each 60 Hz frame pays
//     this; loops that follow each other within a frame find the workers still spinning.
//   * 10,000 empty blocks ..................................... 0.02 µs per block
//   * per element, one thread: vertex update (v += Δv, x += h v, double) 1.7–2.1 ns; a
//     Baraff–Witkin style stretch/shear element (condition, gradient, 9 Hessian blocks written
//     to their slots) 70–85 ns; a 3×3 block-sparse matrix row with 7 blocks (SpMV) 20–22 ns.
//   * 2,400 triangles (the curtain) with that element kernel: speed-up 1.85–1.96 at grains
//     16–256, 1.72 at 512 (5 blocks: one thread gets 3).
//   * 19,481 rows (curtain ×16): SpMV 2.0–2.2× at every grain from 128 to 2048; vertex update
//     fastest at grain 2048 (17.3–17.9 µs vs 34–42 µs serial), 21–25 µs at 256 and 4096.
// Remeasure when the kernels change: numbers from a shared machine, not a benchmark suite.
#pragma once

#include <weft/threading/TaskSystem.h>

namespace weft {

/// Per-vertex loops (integration, vector updates, PCG axpy/dot over vertices): 2048 × ~2 ns
/// ≈ 4 µs per block. The curtain's 1,271 vertices (~2.5 µs in all, less than a fork/join plus
/// the split imbalance) stay one inline block; ×16 gets 10 blocks.
inline constexpr TaskSystem::Index kGrainVertices = 2048;

/// Per-element force loops (triangles, bending hinges): 64 × ~80 ns ≈ 5 µs per block; the
/// curtain's 2,400 triangles make 38 blocks (19 per thread); measured 1.88–1.96× on 2 threads.
inline constexpr TaskSystem::Index kGrainElements = 64;

/// Per-row loops over the block-sparse matrix (SpMV, preconditioner): 128 × ~20 ns ≈ 2.5 µs
/// per block; the curtain's 1,271 rows make 10 blocks (5 per thread, balanced); ×16 measured
/// 2.0–2.2× on 2 threads.
inline constexpr TaskSystem::Index kGrainMatrixRows = 128;

}  // namespace weft
