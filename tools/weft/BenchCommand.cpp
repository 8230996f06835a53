// weft bench: time a scene file's simulation (no rendering) over several runs, each from a freshly
// built world, and print per-frame statistics of each run and of all runs together, with the
// state hash of each run (equal hashes: the runs computed the same bits).
//
// Figures are wall-clock milliseconds on whatever else the machine is doing: compare them as
// ratios between runs of one invocation, not across machines or invocations.
#include "Commands.h"
#include <weft/threading/SampleStatistics.h>

#include <weft/scenes/ScriptedScene.h>

#include <chrono>
#include <iomanip>
#include <numeric>

namespace weft {

int benchScene(const BenchOptions& options, std::ostream& out) {
  Result<SceneDescription> description = loadSceneFile(options.scene);
  if (!description.ok()) {
    out << "weft bench: " << description.error().message << "\n";
    return 1;
  }
  const long frames = options.frames > 0 ? options.frames : std::min<long>(description->frames, 120);
  out << "weft bench " << description->name << ": " << options.repeats << " run(s) of " << frames
      << " frames, simulation only (the first frame of each run is left out)\n";
  std::vector<double> all;
  std::vector<double> medians;
  std::uint64_t firstHash = 0;
  bool sameBits = true;
  for (int run = 0; run < options.repeats; ++run) {
    ScriptedSceneSettings settings;
    settings.threadCount = options.threads;
    Result<ScriptedScene> created = ScriptedScene::create(description.value(), settings);
    if (!created.ok()) {
      out << "weft bench: " << created.error().message << "\n";
      return 1;
    }
    ScriptedScene& scene = created.value();
    std::vector<double> ms;
    for (long frame = 0; frame < frames; ++frame) {
      const auto start = std::chrono::steady_clock::now();
      scene.stepFrame();
      const double elapsed = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      if (frame > 0 || frames == 1) ms.push_back(elapsed);
    }
    const std::uint64_t hash = scene.world().stateHash();
    if (run == 0) firstHash = hash;
    sameBits = sameBits && hash == firstHash;
    medians.push_back(percentile(ms, 50));
    all.insert(all.end(), ms.begin(), ms.end());
    out << std::fixed << std::setprecision(3) << "  run " << run + 1 << "  threads "
        << scene.world().threadCount() << "  ms/frame p50 " << medians.back() << "  p95 "
        << percentile(ms, 95) << "  p99 " << percentile(ms, 99) << "  mean "
        << std::accumulate(ms.begin(), ms.end(), 0.0) / double(ms.size()) << "  state hash 0x"
        << std::hex << hash << std::dec << "\n";
  }
  const double best = *std::min_element(medians.begin(), medians.end());
  const double worst = *std::max_element(medians.begin(), medians.end());
  out << std::fixed << std::setprecision(3) << "  all runs  ms/frame p50 " << percentile(all, 50)
      << "  p95 " << percentile(all, 95) << "  p99 " << percentile(all, 99)
      << "\n  spread    slowest run median / fastest " << std::setprecision(2) << worst / best
      << "\n  determinism  " << (sameBits ? "every run ended with the same state hash"
                                          : "RUNS DIFFER: the state hashes are not equal")
      << "\n";
  return sameBits ? 0 : 3;
}

}  // namespace weft
