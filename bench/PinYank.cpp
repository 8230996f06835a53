// weft-pin-yank: what one pin moved far in one frame costs (issue: pins that jump). A hanging
// cotton sheet held by its two top corners settles; then one corner's target jumps sideways
// towards the other pin, and the frames around the jump are timed and described.
//
//   build/bench/weft-pin-yank [--jump 0.5] [--columns 41] [--pins 2] [--after 60] [--threads 1]
//
// The sheet: 1 m square, `columns` × `columns` vertices, self-collision on (ClothSettings{} with
// the cotton preset). --pins 1 holds it by one corner only: a jump of that pin farther than the
// cloth's size is a teleport (SolverSettings::pinTeleportDistance). With two pins a jump of 1 m
// puts the moved corner on the other; beyond that the pins end farther apart than the cloth
// reaches. Prints each frame from just before the jump for `after` frames (step wall time,
// substeps, largest strain, self-contacts, projection sweeps, impact zones, status) and the worst
// frame against the median of the whole run.
#include "BenchClock.h"

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

int main(int argc, char** argv) {
  using namespace weft;
  CLI::App app{"Frame cost of one pin jumping far in one frame"};
  double jump = 0.5;
  int columns = 41, pins = 2, after = 60, threads = 1, settle = 60;
  app.add_option("--jump", jump, "m the first pin's target moves along +x in one frame")
      ->check(CLI::Range(0.0, 100.0));
  app.add_option("--columns", columns, "Vertices per side")->check(CLI::Range(3, 400));
  app.add_option("--pins", pins, "1: one top corner held, 2: both")->check(CLI::Range(1, 2));
  app.add_option("--settle", settle, "Frames before the jump")->check(CLI::Range(1, 100000));
  app.add_option("--after", after, "Frames from the jump on")->check(CLI::Range(1, 100000));
  app.add_option("--threads", threads, "Threads (1 = serial)")->check(CLI::Range(1, 64));
  CLI11_PARSE(app, argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // a slow frame shows as it ends

  GridSettings grid;
  grid.columns = grid.rows = Index(columns);
  grid.width = grid.height = 1.0;
  grid.origin = Vec3(-0.5, 1.5, 0);
  const auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  settings.material = cottonFabric();
  const Index top = Index((columns - 1) * columns);
  settings.pinnedVertices = {top};
  if (pins == 2) settings.pinnedVertices.push_back(Index(columns * columns - 1));
  WorldSettings worldSettings;
  worldSettings.threadCount = threads;
  World world(worldSettings);
  const ClothId cloth = world.createCloth(model, settings).value();

  std::printf("weft-pin-yank: %d x %d sheet, %d pin(s), jump %.3g m at frame %d, %d thread(s)\n",
              columns, columns, pins, jump, settle, threads);
  std::vector<double> times;
  for (int frame = 0; frame < settle + after; ++frame) {
    if (frame == settle) {
      std::vector<Vec3> targets = world.pinTargets(cloth).value();
      targets[0].x() += jump;
      if (const Status status = world.setPinTargets(cloth, targets); !status) {
        std::printf("setPinTargets refused: %s\n", status.error().message.c_str());
        return 1;
      }
    }
    const double start = bench::wallMs();
    const StepStatus status = world.step(1.0 / 60.0);
    const double ms = bench::wallMs() - start;
    times.push_back(ms);
    if (frame >= settle - 1) {
      const StepStats& stats = world.stats();
      std::printf("  frame %4d: %9.2f ms  substeps %3u  strain %8.3f  self-contacts %7u  "
                  "projection sweeps %5d  impact zones %4u  %s\n",
                  frame, ms, unsigned(stats.substeps), stats.maxStrain,
                  unsigned(stats.selfContacts), stats.strainLimitIterations,
                  unsigned(stats.impactZones), describe(status).c_str());
    }
  }
  std::vector<double> sorted = times;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::printf("median frame %.2f ms, worst %.2f ms (%.1fx the median)\n", median, sorted.back(),
              sorted.back() / median);
  return 0;
}
