// Stage benchmarks on the curtain at every size and on 1 and 2 threads: force and matrix
// assembly, one SpMV, one PCG solve (cold and warm started), and a whole frame. Run in Release:
//   build/bench/weft-bench --benchmark_filter=Curtain
// Arguments are {size, threads}; the state hash printed with the frame benchmark is the same for
// every thread count.
// Each fixture takes the curtain mid-motion (after a few frames of the script), so the solver
// sees a realistic system, and prints the number of PCG iterations as a counter.
#include "ClothForces.h"
#include "CurtainSnapshot.h"

#include <weft/threading/GrainSizes.h>
#include "solver/BlockSparseMatrix.h"
#include "solver/FilteredPcg.h"
#include "solver/VertexFilter.h"

#include <weft/scenes/Curtain.h>

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

namespace weft {
namespace {

constexpr Real kFrameDt = CurtainScene::kFrameDt;

// A curtain a few frames into its script, with its system assembled, built once per size.
struct CurtainSystem {
  std::unique_ptr<CurtainScene> scene;
  std::unique_ptr<ClothForces> forces;
  BlockSparseMatrix matrix;
  VertexFilter filter;
  Vec3Array x, v, f, kv, b;

  explicit CurtainSystem(Index size) {
    CurtainSnapshot snapshot = curtainSnapshot(size);
    scene = std::move(snapshot.scene);
    x = std::move(snapshot.x);
    v = std::move(snapshot.v);
    const ClothModel& model = scene->model();
    forces = std::make_unique<ClothForces>(model, ClothForceSettings{},
                                           model.vertexMasses(ClothMaterial{}.arealDensity));
    matrix.build(model.vertexCount(), forces->coupledPairs());
    forces->bindMatrix(matrix);
    forces->assemble(x, v, kFrameDt, matrix, f, v, kv);
    b.resize(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) b[i] = kFrameDt * (f[i] + kFrameDt * kv[i]);
    filter.resize(model.vertexCount());
    const Index columns = model.gridSize()[0], rows = model.gridSize()[1];
    for (Index c = 0; c < columns; ++c) filter.setFixed((rows - 1) * columns + c, Vec3::Zero());
  }
};

TaskSystem& tasks(int threads) {
  static std::map<int, std::unique_ptr<TaskSystem>> cache;
  std::unique_ptr<TaskSystem>& entry = cache[threads];
  if (!entry) entry = std::make_unique<TaskSystem>(TaskSystemSettings{threads});
  return *entry;
}

CurtainSystem& curtain(Index size) {
  static std::map<Index, std::unique_ptr<CurtainSystem>> cache;
  std::unique_ptr<CurtainSystem>& entry = cache[size];
  if (!entry) entry = std::make_unique<CurtainSystem>(size);
  return *entry;
}

void setCounters(benchmark::State& state, const CurtainSystem& system) {
  state.counters["triangles"] = double(system.scene->model().triangleCount());
  state.counters["blocks"] = double(system.matrix.blockCount());
  state.counters["threads"] = double(state.range(1));
}

void CurtainAssembly(benchmark::State& state) {
  CurtainSystem& system = curtain(Index(state.range(0)));
  system.forces->setTaskSystem(&tasks(int(state.range(1))));
  for (auto _ : state) {
    system.forces->assemble(system.x, system.v, kFrameDt, system.matrix, system.f, system.v, system.kv);
    benchmark::DoNotOptimize(system.matrix.block(0).data());
  }
  setCounters(state, system);
  // Time per triangle (everything the assembly does, bending and per-vertex terms included).
  state.counters["per_triangle"] = benchmark::Counter(
      double(system.scene->model().triangleCount()) * double(state.iterations()),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void CurtainForcesOnly(benchmark::State& state) {
  CurtainSystem& system = curtain(Index(state.range(0)));
  system.forces->setTaskSystem(&tasks(int(state.range(1))));
  for (auto _ : state) {
    benchmark::DoNotOptimize(system.forces->computeForces(system.x, system.v, system.f));
  }
  setCounters(state, system);
}

void CurtainSpmv(benchmark::State& state) {
  CurtainSystem& system = curtain(Index(state.range(0)));
  Vec3Array y(system.x.size());
  TaskSystem& taskSystem = tasks(int(state.range(1)));
  const Index rows = system.matrix.blockRows();
  for (auto _ : state) {
    taskSystem.parallelFor(rows, kGrainMatrixRows, [&](Index begin, Index end, int) {
      system.matrix.multiplyRows(begin, end, system.v, y);
    });
    benchmark::DoNotOptimize(y.data());
  }
  setCounters(state, system);
  // Bytes touched per SpMV: every block (72 B) and column index (4 B), plus x and y.
  state.SetBytesProcessed(std::int64_t(state.iterations()) *
                          std::int64_t(system.matrix.blockCount() * 76 + system.x.size() * 48));
}

void curtainSolve(benchmark::State& state, bool warm) {
  CurtainSystem& system = curtain(Index(state.range(0)));
  FilteredPcg pcg;
  pcg.resize(Index(system.x.size()));
  PcgSettings settings;  // the engine's defaults
  Vec3Array solution(system.x.size(), Vec3::Zero());
  // The warm start a step would have: the solution of the same system, slightly perturbed, is
  // what the previous frame's Δv is like. Solve once to get it.
  TaskSystem& taskSystem = tasks(int(state.range(1)));
  (void)pcg.solve(system.matrix, system.b, system.filter, settings, solution, &taskSystem);
  const Vec3Array previous = solution;
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    for (std::size_t i = 0; i < solution.size(); ++i) {
      solution[i] = warm ? Vec3(0.9 * previous[i]) : Vec3::Zero();
    }
    settings.warmStart = warm;
    state.ResumeTiming();
    const SolveReport report =
        pcg.solve(system.matrix, system.b, system.filter, settings, solution, &taskSystem);
    iterations = report.iterations;
  }
  setCounters(state, system);
  state.counters["cg_iterations"] = iterations;
}

void CurtainSolveCold(benchmark::State& state) { curtainSolve(state, false); }
void CurtainSolveWarm(benchmark::State& state) { curtainSolve(state, true); }

void CurtainFrame(benchmark::State& state) {
  CurtainSettings settings;
  settings.size = Index(state.range(0));
  settings.threadCount = int(state.range(1));
  CurtainScene scene = CurtainScene::create(settings).value();
  scene.stepFrame();  // drop the first step (first touch of every page)
  for (auto _ : state) {
    scene.stepFrame();
    if (scene.frame() >= CurtainScene::kFrames) {
      state.PauseTiming();
      scene = CurtainScene::create(settings).value();
      scene.stepFrame();
      state.ResumeTiming();
    }
  }
  state.counters["triangles"] = double(scene.model().triangleCount());
  state.counters["threads"] = double(state.range(1));
  state.counters["cg_iterations"] = scene.world().stats().cgIterations;
  state.counters["state_hash_low"] = double(scene.world().stateHash() & 0xffff);
}

#define WEFT_CURTAIN_SIZES \
  ->ArgsProduct({{1, 4, 16, 64}, {1, 2}})->ArgNames({"size", "threads"})->Unit(benchmark::kMillisecond)
BENCHMARK(CurtainAssembly) WEFT_CURTAIN_SIZES;
BENCHMARK(CurtainForcesOnly) WEFT_CURTAIN_SIZES;
BENCHMARK(CurtainSpmv) WEFT_CURTAIN_SIZES;
BENCHMARK(CurtainSolveCold) WEFT_CURTAIN_SIZES;
BENCHMARK(CurtainSolveWarm) WEFT_CURTAIN_SIZES;
BENCHMARK(CurtainFrame) WEFT_CURTAIN_SIZES;

}  // namespace
}  // namespace weft
