// What skipping unneeded stages and sleeping save, and what a frame budget buys.
//   build/bench/weft-bench --benchmark_filter='Hold|Resting|Budget|PinnedFlag|CurtainPins|FoldedStrip|BvhRefit'
//
// CurtainHold: the curtain's hold phase (6–8 s: gathered, pins still, heavy self-contact), one
// frame per iteration, restarting from a save at 6 s when the phase ends. mode 0: every stage
// runs, no sleep; mode 1: stages the scene does not need are skipped; mode 2: skips and sleeping
// (the defaults). CurtainResting: the curtain with its rod held still and no sphere, settled for
// 8 s before timing: a cloth at rest. Time ratios between modes are the savings.
// CurtainBudget: the full 600-frame script within a budget of 1, 2, 4 or 8 ms per frame: the share
// of frames that met it, frames that ran a relaxed plan, the largest PCG residual and strain, and
// the RMS distance of the vertices from an unbudgeted run of the same script (mean over frames,
// relative to the 2 m width). One iteration each; the numbers depend on the machine's load.
// PinnedFlag: a 41 × 31 flag held on two edges (pole and top: 71 pins) whose pins wave, one frame
// per iteration; mode 0 keeps the pins in the implicit system (filtered), mode 1 removes them
// (SolverSettings::removePinnedVertices, the default). CurtainPins: the same switch on the
// curtain's first 4 s (41 pins). FoldedStripRefit: a 21 × 81 strip folded in two on the floor,
// its upper end lifted and swung: mode 0 refits the whole self-collision BVH every time, mode 1
// keeps the boxes of the resting layer (skipUnneededStages); counters give nodes refit and kept.
// (Mode 1 also turns on the other skips, whose checks cost a little here since none applies.)
// BvhRefitHalfResting: the refit alone on the ×16 curtain's grid (38,400 triangles), half of it
// moving 1 cm a refit and half still: margin −1 (refit all) against 60 µm (the engine's).
#include <weft/collision/Bvh.h>
#include <weft/collision/Plane.h>
#include <weft/engine/World.h>
#include <weft/scenes/Curtain.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace weft {
namespace {

// mode 0: every stage, no sleep; 1: skips, no sleep; 2: skips and sleep (the defaults).
CurtainSettings settingsFor(std::int64_t mode) {
  CurtainSettings settings;
  settings.threadCount = 1;
  settings.skipUnneededStages = mode >= 1;
  settings.sleep = mode >= 2;
  return settings;
}

void CurtainHold(benchmark::State& state) {
  CurtainScene scene = CurtainScene::create(settingsFor(state.range(0))).value();
  constexpr Index kHoldStart = 360, kHoldEnd = 480;
  while (scene.frame() < kHoldStart) scene.stepFrame();
  const WorldState saved = scene.world().saveState();
  Index sleeping = 0, selfPasses = 0, frames = 0;
  for (auto _ : state) {
    scene.stepFrame();
    sleeping += scene.world().stats().sleepingCloths;
    selfPasses += scene.world().stats().selfCollisionPasses;
    ++frames;
    if (scene.frame() >= kHoldEnd) {
      state.PauseTiming();
      (void)scene.world().restoreState(saved);
      scene.rewindTo(kHoldStart);
      state.ResumeTiming();
    }
  }
  state.counters["sleeping_frames"] = double(sleeping) / double(frames);
  state.counters["self_passes"] = double(selfPasses) / double(frames);
}

void CurtainResting(benchmark::State& state) {
  CurtainSettings settings = settingsFor(state.range(0));
  settings.pinScript = false;
  settings.sphere = false;  // no push: the curtain only settles its initial pleats
  CurtainScene scene = CurtainScene::create(settings).value();
  while (scene.frame() < 480) scene.stepFrame();  // 8 s: it sleeps after about 6 s
  Index sleeping = 0, frames = 0;
  for (auto _ : state) {
    scene.stepFrame();
    sleeping += scene.world().stats().sleepingCloths;
    ++frames;
  }
  state.counters["sleeping_frames"] = double(sleeping) / double(frames);
}

void CurtainBudget(benchmark::State& state) {
  const Real budgetMs = Real(state.range(0));
  for (auto _ : state) {
    CurtainScene reference = CurtainScene::create(settingsFor(2)).value();
    CurtainScene budgeted = CurtainScene::create(settingsFor(2)).value();
    StepBudget budget;
    budget.milliseconds = budgetMs;
    Index misses = 0, relaxed = 0;
    Real residual = 0, strain = 0, squaredError = 0, referenceStrain = 0;
    for (Index frame = 0; frame < CurtainScene::kFrames; ++frame) {
      reference.stepFrame();
      referenceStrain = std::max(referenceStrain, reference.world().stats().maxStrain);
      misses += hasFlag(budgeted.stepFrame(budget), StepStatus::BudgetMissed);
      const StepStats& stats = budgeted.world().stats();
      relaxed += !(stats.plan == StepPlan{});
      residual = std::max(residual, stats.cgResidual);
      strain = std::max(strain, stats.maxStrain);
      const auto a = reference.world().positions(reference.cloth()).value();
      const auto b = budgeted.world().positions(budgeted.cloth()).value();
      Real sum = 0;
      for (std::size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]).squaredNorm();
      squaredError += sum / Real(a.size());
    }
    const Real frames = Real(CurtainScene::kFrames);
    state.counters["hit_rate"] = 1 - Real(misses) / frames;
    state.counters["relaxed_frames"] = Real(relaxed);
    state.counters["cg_residual_max"] = residual;
    state.counters["max_strain"] = strain;
    state.counters["max_strain_unbudgeted"] = referenceStrain;
    state.counters["rms_error_rel"] = std::sqrt(squaredError / frames) / 2.0;
  }
}

std::shared_ptr<const ClothModel> gridModel(Index columns, Index rows, Real width, Real height) {
  GridSettings grid;
  grid.columns = columns;
  grid.rows = rows;
  grid.width = width;
  grid.height = height;
  grid.origin = Vec3(0, 1, 0);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

void PinnedFlag(benchmark::State& state) {
  constexpr Index kColumns = 41, kRows = 31;
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  World world(worldSettings);
  ClothSettings settings;
  for (Index r = 0; r < kRows; ++r) settings.pinnedVertices.push_back(r * kColumns);
  for (Index c = 1; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  settings.solver.removePinnedVertices = state.range(0) == 1;
  settings.sleep.enabled = false;
  const ClothId cloth = world.createCloth(gridModel(kColumns, kRows, 1.2, 0.9), settings).value();
  const std::vector<Vec3> rest = world.pinTargets(cloth).value();
  std::vector<Vec3> targets = rest;
  Index frame = 0, unknowns = 0, iterations = 0;
  for (auto _ : state) {
    const Real t = Real(++frame) / 60;
    for (std::size_t k = 0; k < targets.size(); ++k) {
      targets[k] = rest[k] + Vec3(0, 0.03 * std::sin(9 * t) * rest[k].x(), 0.1 * std::sin(6 * t));
    }
    (void)world.setPinTargets(cloth, targets);
    world.step(1.0 / 60);
    unknowns = world.stats().solvedUnknowns;
    iterations += world.stats().cgIterations;
  }
  state.counters["unknowns"] = double(unknowns);
  state.counters["cg_iterations"] = double(iterations) / double(frame);
  state.counters["state_hash_low"] = double(world.stateHash() & 0xffff);
}

void CurtainPins(benchmark::State& state) {
  CurtainSettings settings = settingsFor(1);  // skips on, no sleep
  settings.solver.removePinnedVertices = state.range(0) == 1;
  CurtainScene scene = CurtainScene::create(settings).value();
  const WorldState start = scene.world().saveState();
  constexpr Index kEnd = 240;  // settle, push, withdraw, rest
  Index unknowns = 0;
  for (auto _ : state) {
    scene.stepFrame();
    unknowns = scene.world().stats().solvedUnknowns;
    if (scene.frame() >= kEnd) {
      state.PauseTiming();
      (void)scene.world().restoreState(start);
      scene.rewindTo(0);
      state.ResumeTiming();
    }
  }
  state.counters["unknowns"] = double(unknowns);
}

void FoldedStripRefit(benchmark::State& state) {
  constexpr Index kColumns = 21, kRows = 81;
  constexpr Real kSpacing = 0.025;
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  worldSettings.skipUnneededStages = state.range(0) == 1;
  World world(worldSettings);
  (void)world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  settings.sleep.enabled = false;
  const auto model = gridModel(kColumns, kRows, (kColumns - 1) * kSpacing, (kRows - 1) * kSpacing);
  const ClothId cloth = world.createCloth(model, settings).value();
  // Rows 0–40 lie on the floor, rows 41–80 folded back over them 1 cm higher.
  std::vector<Vec3> positions(model->vertexCount());
  for (Index r = 0; r < kRows; ++r) {
    for (Index c = 0; c < kColumns; ++c) {
      const bool lower = r <= kRows / 2;
      positions[r * kColumns + c] = Vec3(c * kSpacing, lower ? 0.0035 : 0.0135,
                                         (lower ? r : kRows - 1 - r) * kSpacing);
    }
  }
  (void)world.setState(cloth, positions, std::vector<Vec3>(positions.size(), Vec3::Zero()));
  std::vector<Vec3> start;
  for (Index c = 0; c < kColumns; ++c) start.push_back(positions[(kRows - 1) * kColumns + c]);
  std::vector<Vec3> targets = start;
  Index frame = 0;
  const auto stepOnce = [&] {
    const Real t = Real(++frame) / 60;
    for (std::size_t k = 0; k < targets.size(); ++k) {
      targets[k] = start[k] + Vec3(0.1 * std::sin(4 * t), 0.3 * std::min<Real>(t / 0.5, 1), 0);
    }
    (void)world.setPinTargets(cloth, targets);
    world.step(1.0 / 60);
  };
  while (frame < 30) stepOnce();  // lifted: the upper layer is off the lower one
  Index refit = 0, kept = 0, frames = 0;
  for (auto _ : state) {
    stepOnce();
    refit += world.stats().bvhNodesRefit;
    kept += world.stats().bvhNodesSkipped;
    ++frames;
  }
  state.counters["bvh_refit_per_frame"] = double(refit) / double(frames);
  state.counters["bvh_kept_per_frame"] = double(kept) / double(frames);
  state.counters["self_passes"] = double(world.stats().selfCollisionPasses);
}

void BvhRefitHalfResting(benchmark::State& state) {
  GridSettings grid;
  grid.columns = 161;
  grid.rows = 121;
  const ClothModel model = ClothModel::grid(grid).value();
  Bvh tree = Bvh::build(model.indices(), model.restPositions()).value();
  tree.setRefitMargin(state.range(0) == 1 ? 6e-5 : -1);
  std::vector<Vec3> previous = model.restPositions(), current = previous;
  Index refit = 0, kept = 0, step = 0;
  for (auto _ : state) {
    ++step;
    for (std::size_t v = 0; v < current.size(); ++v) {
      if (model.restPositions()[v].x() > 0) current[v].z() = 0.01 * Real(step % 50);
    }
    tree.refit(previous, current, 0.003);
    refit += tree.lastRefitCounts().refitNodes;
    kept += tree.lastRefitCounts().skippedNodes;
    std::swap(previous, current);
    current = previous;
  }
  state.counters["refit_per_call"] = double(refit) / double(step);
  state.counters["kept_per_call"] = double(kept) / double(step);
}

BENCHMARK(BvhRefitHalfResting)->Arg(0)->Arg(1)->ArgName("skip")->Unit(benchmark::kMicrosecond);
BENCHMARK(PinnedFlag)->Arg(0)->Arg(1)->ArgName("remove")->Unit(benchmark::kMillisecond);
BENCHMARK(CurtainPins)->Arg(0)->Arg(1)->ArgName("remove")->Unit(benchmark::kMillisecond);
BENCHMARK(FoldedStripRefit)->Arg(0)->Arg(1)->ArgName("skip")->Unit(benchmark::kMillisecond);
BENCHMARK(CurtainHold)->Arg(0)->Arg(1)->Arg(2)->ArgName("mode")->Unit(benchmark::kMillisecond);
BENCHMARK(CurtainResting)->Arg(0)->Arg(1)->Arg(2)->ArgName("mode")->Unit(benchmark::kMillisecond);
BENCHMARK(CurtainBudget)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->ArgName("budget_ms")->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace weft
