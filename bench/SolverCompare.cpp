// weft-solver-compare: block-Jacobi, multicolour Gauss–Seidel and two-level Gauss–Seidel PCG on
// the scenes that decide the default (the curtain ×1, ×4 and ×16 on request, stress scene 2's
// stiff sheet), in one process.
//
//   build/bench/weft-solver-compare [--frames 600] [--sizes 1,4] [--threads 1] [--repeats 2]
//
// Every run is repeated and the preconditioners alternate (J, G, T, J, G, T, …), so a machine
// shared with other jobs slows them alike; a frame's time is the calling thread's CPU time for
// World::step (plus wall time, which also shows waits), the smaller of the repeats is kept. The
// report gives, per scene: PCG iterations per solve (mean, max), solves at the cap, solve ms
// (World's own wall-clock measure), simulation CPU ms per frame and the ratios to Gauss–Seidel,
// and the curtain's state hash per preconditioner (thread-count independent; compare with
// weft-curtain).
#include "BenchClock.h"

#include <weft/scenes/Curtain.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cinttypes>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

namespace weft {
namespace {

using bench::threadCpuMs;
using bench::wallMs;

struct RunFigures {
  long solves = 0;
  long iterations = 0;
  int maxIterationsPerFrame = 0;
  int capFrames = 0;     ///< frames with StepStatus::SolverNotConverged
  double solveMs = 0;    ///< summed StepStats::solveMs
  double cpuMs = 0;      ///< summed thread CPU time of step()
  double wallMs = 0;     ///< summed wall time of step()
  int frames = 0;
  std::uint64_t hash = 0;
  double maxStrain = 0;

  void add(const StepStats& stats, double cpu, double wall) {
    solves += stats.linearSolves;
    iterations += stats.cgIterations;
    maxIterationsPerFrame = std::max(maxIterationsPerFrame, stats.cgIterations);
    if (hasFlag(stats.status, StepStatus::SolverNotConverged)) ++capFrames;
    solveMs += stats.solveMs;
    cpuMs += cpu;
    wallMs += wall;
    maxStrain = std::max(maxStrain, double(stats.maxStrain));
    ++frames;
  }
  /// Keeps, per time figure, the smaller of two repeats (the least disturbed by other jobs).
  void keepFaster(const RunFigures& other) {
    solveMs = std::min(solveMs, other.solveMs);
    cpuMs = std::min(cpuMs, other.cpuMs);
    wallMs = std::min(wallMs, other.wallMs);
  }
};

const char* name(PreconditionerKind kind) {
  switch (kind) {
    case PreconditionerKind::BlockJacobi: return "block-Jacobi";
    case PreconditionerKind::MulticolorGaussSeidel: return "MC Gauss-Seidel";
    case PreconditionerKind::TwoLevelGaussSeidel: break;
  }
  return "two-level";
}

RunFigures runCurtain(Index size, int frames, int threads, PreconditionerKind kind) {
  CurtainSettings settings;
  settings.size = size;
  settings.threadCount = threads;
  settings.solver.preconditioner = kind;
  CurtainScene scene = CurtainScene::create(settings).value();
  RunFigures figures;
  for (int frame = 0; frame < frames; ++frame) {
    const double cpu = threadCpuMs(), wall = wallMs();
    scene.stepFrame();
    figures.add(scene.world().stats(), threadCpuMs() - cpu, wallMs() - wall);
  }
  figures.hash = scene.world().stateHash();
  return figures;
}

/// Stress scene 2 (tests/stress/StiffnessRangeTest.cpp): a 13 × 13, 0.6 m cotton square pinned
/// along one edge swings down for 90 frames, every stiffness × factor.
RunFigures runStiffSheet(Real factor, int threads, PreconditionerKind kind) {
  constexpr Index kVertices = 13;
  GridSettings grid;
  grid.columns = grid.rows = kVertices;
  grid.width = grid.height = 0.6;
  grid.origin = Vec3(-0.3, 1.0, 0.3);
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, 0, -1);
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  WorldSettings worldSettings;
  worldSettings.threadCount = threads;
  World world(worldSettings);
  ClothSettings settings;
  settings.material.warpStretchStiffness *= factor;
  settings.material.weftStretchStiffness *= factor;
  settings.material.shearStiffness *= factor;
  settings.material.bendingStiffness *= factor;
  settings.solver.preconditioner = kind;
  for (Index c = 0; c < kVertices; ++c) settings.pinnedVertices.push_back(c);
  world.createCloth(model, settings).value();
  RunFigures figures;
  for (int frame = 0; frame < 90; ++frame) {
    const double cpu = threadCpuMs(), wall = wallMs();
    world.step(1.0 / 60.0);
    figures.add(world.stats(), threadCpuMs() - cpu, wallMs() - wall);
  }
  figures.hash = world.stateHash();
  return figures;
}

/// The preconditioners compared, in the order they run within each repeat.
constexpr std::array<PreconditionerKind, 3> kKinds = {PreconditionerKind::BlockJacobi,
                                                      PreconditionerKind::MulticolorGaussSeidel,
                                                      PreconditionerKind::TwoLevelGaussSeidel};

void print(const std::string& scene, const std::array<RunFigures, kKinds.size()>& figures) {
  const auto perSolve = [](const RunFigures& f) {
    return double(f.iterations) / double(std::max(1L, f.solves));
  };
  for (std::size_t k = 0; k < kKinds.size(); ++k) {
    const RunFigures& f = figures[k];
    std::printf("  %-16s %-16s it/solve %6.1f  max/frame %4d  cap frames %3d  solve ms/frame %7.3f"
                "  cpu ms/frame %7.3f  wall ms/frame %7.3f  strain %.4f  hash 0x%016" PRIx64 "\n",
                scene.c_str(), name(kKinds[k]), perSolve(f), f.maxIterationsPerFrame, f.capFrames,
                f.solveMs / f.frames, f.cpuMs / f.frames, f.wallMs / f.frames, f.maxStrain, f.hash);
  }
  // Ratios against multicolour Gauss–Seidel, the preconditioner below the two-level threshold.
  const RunFigures& base = figures[1];
  for (std::size_t k : {std::size_t(0), std::size_t(2)}) {
    const RunFigures& f = figures[k];
    std::printf("  %-16s ratio %s / Gauss-Seidel: iterations %.3f  solve ms %.3f  cpu ms/frame %.3f"
                "  wall %.3f\n",
                scene.c_str(), name(kKinds[k]), perSolve(f) / perSolve(base),
                f.solveMs / base.solveMs, f.cpuMs / base.cpuMs, f.wallMs / base.wallMs);
  }
  std::printf("\n");
}

template <typename Run>
void compare(const std::string& scene, int repeats, Run&& run) {
  std::array<RunFigures, kKinds.size()> figures;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    for (std::size_t k = 0; k < kKinds.size(); ++k) {
      RunFigures f = run(kKinds[k]);
      if (repeat == 0) {
        figures[k] = f;
      } else {
        figures[k].keepFaster(f);
      }
    }
  }
  print(scene, figures);
}

}  // namespace
}  // namespace weft

int main(int argc, char** argv) {
  using namespace weft;
  CLI::App app{
      "Block-Jacobi, multicolour Gauss-Seidel and two-level PCG on the curtain and stress scene 2"};
  int frames = 600;
  int threads = 1;
  int repeats = 2;
  std::vector<unsigned> sizes = {1, 4};
  bool sheet = true;
  app.add_option("--frames", frames, "Curtain frames per run")->check(CLI::Range(1, 100000));
  app.add_option("--threads", threads, "Threads (1 = serial reference)")->check(CLI::Range(1, 64));
  app.add_option("--repeats", repeats, "Runs per preconditioner (fastest kept)")->check(CLI::Range(1, 20));
  app.add_option("--sizes", sizes, "Curtain sizes (1, 4, 16, 64; none: --sizes 0)")->delimiter(',');
  app.add_option("--sheet", sheet, "Also run stress scene 2 (true/false)");
  CLI11_PARSE(app, argc, argv);

  std::printf("weft-solver-compare: %d curtain frames, %d thread(s), %d repeat(s)\n\n", frames,
              threads, repeats);
  for (unsigned size : sizes) {
    if (size == 0) continue;
    compare("curtain x" + std::to_string(size), repeats,
            [&](PreconditionerKind kind) { return runCurtain(size, frames, threads, kind); });
  }
  if (sheet) {
    for (Real factor : {1.0, 10.0, 100.0, 1e3, 1e4}) {
      compare("sheet x" + std::to_string(static_cast<long>(factor)), repeats,
              [&](PreconditionerKind kind) { return runStiffSheet(factor, threads, kind); });
    }
  }
  return 0;
}
