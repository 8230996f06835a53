// What skipping unneeded stages and sleeping save, and what a frame budget buys.
//   build/bench/weft-bench --benchmark_filter='Hold|Resting|Budget'
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
#include <weft/scenes/Curtain.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
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

BENCHMARK(CurtainHold)->Arg(0)->Arg(1)->Arg(2)->ArgName("mode")->Unit(benchmark::kMillisecond);
BENCHMARK(CurtainResting)->Arg(0)->Arg(1)->Arg(2)->ArgName("mode")->Unit(benchmark::kMillisecond);
BENCHMARK(CurtainBudget)->Arg(1)->Arg(2)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->ArgName("budget_ms")->Iterations(1)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace weft
