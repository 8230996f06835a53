// One PCG iteration against the memory-bandwidth bound of one SpMV + preconditioner application,
// on the curtain's implicit system at ×1, ×4 and ×16, on 1 and 2 threads:
//   build/bench/weft-bench --benchmark_filter=PcgIteration --benchmark_repetitions=5
//
// The system is the engine's: the cotton curtain a few frames into its script, assembled by
// ClothForces with the pinned rod removed from the rows (FreeVertexMap), the rows coloured from
// the mesh as a Cloth colours them, solved with SolverSettings' defaults (multicolour Gauss–Seidel,
// the velocity-error test). The time of one iteration is the difference of two solves run to a
// fixed iteration count (tolerance 0), so set-up (preconditioner, packing) is left out.
//
// The bound is bytes / bandwidth. Bytes of one SpMV + preconditioner application: every stored
// block and its column index (an isotropic block as one scalar, as the sweeps store it), the row
// offsets, the preconditioner's n diagonal blocks, and four vectors of n Vec3 (x read and y
// written by the SpMV, r read and z written by the preconditioner).
// The Gauss–Seidel iteration (Eisenstat's form) moves the same matrix bytes: its two half-sweeps
// read every off-diagonal block once and D̃⁻¹ twice (the second read is left out: the bound stays
// a lower bound). Bandwidth: a STREAM triad a = b + s·c,
// measured in the same benchmark body right before the solves, with the same thread count, twice:
// on 3 × 64 MB arrays (memory: larger than the last-level cache) and on arrays the size of the
// iteration's bytes (the cache level the system fits in). Each time is the best of several runs,
// on the wall clock or (argument cpu:1) in CPU seconds of the process, for the triad and the
// solves alike: on a shared machine the wall clock mostly measures waiting for a core.
// Counters (per benchmark):
//   iteration_us   measured time of one PCG iteration (the benchmark's time is the same)
//   bound_us       bytes / memory triad bandwidth;   ratio = iteration_us / bound_us
//   cache_bound_us bytes / same-size triad bandwidth; cache_ratio = iteration_us / cache_bound_us
//   bytes, memory_GBps, cache_GBps, default_iterations (a default solve from Δv = 0),
//   blocks and isotropic_blocks (stored blocks, and those that are multiples of the identity)
#include "ClothForces.h"
#include "CurtainSnapshot.h"

#include "solver/BlockSparseMatrix.h"
#include "solver/FilteredPcg.h"
#include "solver/FreeVertexMap.h"
#include "solver/MulticolorOrdering.h"
#include "solver/PinnedCoupling.h"
#include "solver/VertexFilter.h"

#include <weft/scenes/Curtain.h>

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <memory>

namespace weft {
namespace {

// The engine's implicit system of the curtain a few frames into its script, built once per size.
struct CurtainPcgSystem {
  std::unique_ptr<CurtainScene> scene;
  std::unique_ptr<ClothForces> forces;
  FreeVertexMap map;
  PinnedCoupling coupling;
  BlockSparseMatrix matrix;
  VertexFilter filter;       // by row: every row free (the pins have no row)
  Vec3Array b;               // by row
  std::vector<Real> rowMass;
  std::vector<Index> rowColors;

  explicit CurtainPcgSystem(Index size) {
    CurtainSnapshot snapshot = curtainSnapshot(size);
    const CurtainSettings& settings = snapshot.settings;
    scene = std::move(snapshot.scene);
    const Vec3Array& x = snapshot.x;
    const Vec3Array& v = snapshot.v;
    const ClothModel& model = scene->model();
    ClothForceSettings forceSettings;
    forceSettings.material = settings.material;
    const std::vector<Real> masses = model.vertexMasses(settings.material.arealDensity);
    forces = std::make_unique<ClothForces>(model, forceSettings, masses);

    // The rod's pins leave the system, as Cloth removes them.
    const Index columns = model.gridSize()[0], rows = model.gridSize()[1];
    std::vector<Index> pinned;
    for (Index c = 0; c < columns; ++c) pinned.push_back((rows - 1) * columns + c);
    map.build(model.vertexCount(), pinned);
    forces->buildSystem(map, matrix, coupling);
    const std::vector<Index> vertexColors =
        MulticolorOrdering::colorVertices(model.vertexCount(), forces->potentialCoupledPairs());

    const Real h = CurtainScene::kFrameDt;
    Vec3Array f, kv, rhs(x.size());
    forces->assemble(x, v, h, matrix, f, v, kv, &coupling);
    for (std::size_t i = 0; i < x.size(); ++i) rhs[i] = h * (f[i] + h * kv[i]);
    b.resize(map.rowCount());
    map.gather(rhs, b);
    filter.resize(map.rowCount());
    rowMass.resize(map.rowCount());
    rowColors.resize(map.rowCount());
    for (Index row = 0; row < map.rowCount(); ++row) {
      rowMass[row] = masses[map.vertex(row)];
      rowColors[row] = vertexColors[map.vertex(row)];
    }
  }
};

CurtainPcgSystem& pcgSystem(Index size) {
  static std::map<Index, std::unique_ptr<CurtainPcgSystem>> cache;
  std::unique_ptr<CurtainPcgSystem>& entry = cache[size];
  if (!entry) entry = std::make_unique<CurtainPcgSystem>(size);
  return *entry;
}

TaskSystem& pcgTasks(int threads) {
  static std::map<int, std::unique_ptr<TaskSystem>> cache;
  std::unique_ptr<TaskSystem>& entry = cache[threads];
  if (!entry) entry = std::make_unique<TaskSystem>(TaskSystemSettings{threads});
  return *entry;
}

/// Seconds on the wall clock, or of CPU time used by the process (all its threads): the clock of
/// a shared machine, where a wall-clock interval mostly measures waiting for a core.
double now(bool cpuTime) {
  if (!cpuTime) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  timespec time{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &time);
  return double(time.tv_sec) + 1e-9 * double(time.tv_nsec);
}

/// STREAM triad a = b + s·c over `count` doubles per array on `tasks`: the best of `repeats`
/// passes, in bytes per second of `now(cpuTime)` (3 × 8 bytes per element, STREAM's convention).
double triadBandwidth(std::size_t count, TaskSystem& tasks, int repeats, bool cpuTime) {
  static std::vector<double> a, b, c;
  if (a.size() < count) {
    a.assign(count, 1.0);
    b.assign(count, 2.0);
    c.assign(count, 0.5);
  }
  constexpr Index kGrain = 1 << 14;
  double best = 1e30;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    const double start = now(cpuTime);
    tasks.parallelFor(Index(count), kGrain, [&](Index begin, Index end, int) {
      for (Index i = begin; i < end; ++i) a[i] = b[i] + 3.0 * c[i];
    });
    benchmark::ClobberMemory();
    best = std::min(best, now(cpuTime) - start);
  }
  benchmark::DoNotOptimize(a.data());
  return 3.0 * sizeof(double) * double(count) / best;
}

void PcgIteration(benchmark::State& state) {
  CurtainPcgSystem& system = pcgSystem(Index(state.range(0)));
  TaskSystem& tasks = pcgTasks(int(state.range(1)));
  const PreconditionerKind kind =
      state.range(2) == 0 ? PreconditionerKind::MulticolorGaussSeidel : PreconditionerKind::BlockJacobi;
  const bool cpuTime = state.range(3) != 0;
  const Index n = system.matrix.blockRows();
  const double blocks = double(system.matrix.blockCount());
  double isotropicBlocks = 0;
  for (Index slot = 0; slot < system.matrix.blockCount(); ++slot) {
    isotropicBlocks += system.matrix.isotropic(slot) ? 1 : 0;
  }
  // An isotropic block is one scalar (BlockSparseMatrix::isotropic()), the others a Mat3.
  const double bytes = (blocks - isotropicBlocks) * (sizeof(Mat3) + sizeof(Index)) +
                       isotropicBlocks * (sizeof(Real) + sizeof(Index)) +
                       double(n + 1) * sizeof(Index) + double(n) * sizeof(Mat3) +
                       4.0 * double(n) * sizeof(Vec3);

  FilteredPcg pcg;
  pcg.resize(n);
  pcg.setRowColors(system.rowColors);
  PcgSettings settings;  // the engine's solve (ImplicitEuler::solve with SolverSettings{})
  const SolverSettings defaults;
  settings.tolerance = defaults.cgTolerance;
  settings.stopping = defaults.cgStopping;
  settings.preconditioner = kind;
  settings.warmStart = false;
  Vec3Array deltaV(n, Vec3::Zero());
  const int defaultIterations =
      pcg.solve(system.matrix, system.b, system.filter, settings, deltaV, &tasks, system.rowMass)
          .iterations;

  // Fixed iteration counts: tolerance 0 never stops before the cap.
  settings.tolerance = 0;
  settings.absoluteTolerance = 0;
  constexpr int kShort = 5, kLong = 45, kSolveRepeats = 7;
  const auto timeSolve = [&](int iterations) {
    settings.maxIterations = iterations;
    std::fill(deltaV.begin(), deltaV.end(), Vec3::Zero());
    const double start = now(cpuTime);
    const SolveReport report =
        pcg.solve(system.matrix, system.b, system.filter, settings, deltaV, &tasks, system.rowMass);
    const double elapsed = now(cpuTime) - start;
    if (report.iterations != iterations) state.SkipWithError("the solve ended before its cap");
    return elapsed;
  };
  double memoryBandwidth = 0, cacheBandwidth = 0, iterationSeconds = 0;
  for (auto _ : state) {
    memoryBandwidth = triadBandwidth(std::size_t(8) << 20, tasks, 3, cpuTime);  // 3 × 64 MB
    cacheBandwidth = triadBandwidth(std::size_t(bytes / 24), tasks, 20, cpuTime);
    // The best of several solves of each length, as the triad takes its best pass: on a shared
    // machine a solve is only ever slowed down.
    double shortSolve = 1e30, longSolve = 1e30;
    for (int repeat = 0; repeat < kSolveRepeats; ++repeat) {
      shortSolve = std::min(shortSolve, timeSolve(kShort));
      longSolve = std::min(longSolve, timeSolve(kLong));
    }
    iterationSeconds = (longSolve - shortSolve) / (kLong - kShort);
    state.SetIterationTime(iterationSeconds);
  }
  const double bound = bytes / memoryBandwidth, cacheBound = bytes / cacheBandwidth;
  state.counters["rows"] = n;
  state.counters["blocks"] = blocks;
  state.counters["isotropic_blocks"] = isotropicBlocks;
  state.counters["bytes"] = bytes;
  state.counters["iteration_us"] = 1e6 * iterationSeconds;
  state.counters["bound_us"] = 1e6 * bound;
  state.counters["ratio"] = iterationSeconds / bound;
  state.counters["cache_bound_us"] = 1e6 * cacheBound;
  state.counters["cache_ratio"] = iterationSeconds / cacheBound;
  state.counters["memory_GBps"] = 1e-9 * memoryBandwidth;
  state.counters["cache_GBps"] = 1e-9 * cacheBandwidth;
  state.counters["default_iterations"] = defaultIterations;
}

// Arguments {size, threads, preconditioner (0 Gauss–Seidel, the default; 1 block Jacobi),
// clock (0 wall; 1 the process's CPU time, summed over its threads, for a shared machine)}.
BENCHMARK(PcgIteration)
    ->ArgsProduct({{1, 4, 16}, {1, 2}, {0, 1}, {0, 1}})
    ->ArgNames({"size", "threads", "jacobi", "cpu"})
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace weft
