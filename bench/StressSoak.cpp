// weft-stress-soak: the long variants of the stress suite (tests/stress/ holds the short
// ones that run in CI).
//
//   soak     scene 12: the curtain (its geometry and material, sphere and floor) in a
//            steady wind for an hour of simulated time, its 10 s script (sphere push, gather,
//            re-open) repeated throughout (--script off holds the rod still; in a steady wind the
//            curtain then comes to rest within a minute and the soak measures a cloth at rest). Samples the resident
//            memory (/proc/self/statm) and the mean step time over windows of simulated time, and
//            says whether memory grew and whether the step time drifted (mean of the last 10 % of
//            windows over the first 10 %). Every window also checks the state is finite and, with
//            --check-intersections, that no triangle pair intersects.
//   steps    scene 1 in full: the whole 10 s curtain script at one implicit step per frame for
//            frame steps 1/600 … 1/15 s, with the error against the 1/600 s run at every second.
//
// Timings are wall-clock on whatever machine runs it: compare ratios from one run, not absolute
// numbers across machines. The soak also samples the process's CPU time per step and the PCG
// iterations per step: on a machine whose load changes during the hour, CPU time per PCG
// iteration is the drift measure that other jobs disturb least (run it with --threads 1 so CPU
// time is the step's own work, not the pool's spinning).
#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/scenes/Curtain.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <string>
#include <time.h>
#include <unistd.h>
#include <vector>

namespace {

using namespace weft;

// MB resident, from /proc/self/statm (second field, in pages).
double residentMegabytes() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return double(resident) * double(sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

// CPU time of the whole process, ms.
double processCpuMilliseconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return double(now.tv_sec) * 1e3 + double(now.tv_nsec) * 1e-6;
}

struct SoakOptions {
  double minutes = 60;       // simulated
  double windowSeconds = 30; // simulated time per sample
  double wind = 4;           // m/s along +z
  int threads = 0;
  bool selfCollision = true;
  bool checkIntersections = false;
  bool script = true;  // repeat the curtain's 10 s script
  std::string csv;
};

int runSoak(const SoakOptions& options) {
  GridSettings grid;  // the defaults are the curtain's geometry
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  WorldSettings worldSettings;
  worldSettings.wind = Vec3(0, 0, options.wind);
  worldSettings.threadCount = options.threads;
  World world(worldSettings);
  ClothSettings settings;
  settings.selfCollision = options.selfCollision;
  for (Index c = 0; c < grid.columns; ++c) settings.pinnedVertices.push_back((grid.rows - 1) * grid.columns + c);
  const ClothId cloth = world.createCloth(model, settings).value();
  RigidMotion sphereMotion;
  sphereMotion.pose.position = CurtainScene::spherePosition(0);
  const ColliderId sphere =
      world.addCollider(Sphere::create(CurtainScene::kSphereRadius, sphereMotion).value()).value();
  (void)world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  SelfIntersectionCounter counter =
      SelfIntersectionCounter::create(model->indices(), model->restPositions()).value();

  const double frameDt = CurtainScene::kFrameDt;
  const long framesPerWindow = std::max(1L, std::lround(options.windowSeconds / frameDt));
  const long windows = std::max(1L, std::lround(options.minutes * 60 / options.windowSeconds));
  std::vector<double> rss, stepMs, cpuMs, iterations;
  long retried = 0, rolledBack = 0, capped = 0, intersecting = 0;
  bool finite = true;
  std::ofstream csv;
  if (!options.csv.empty()) {
    csv.open(options.csv);
    csv << "window,simulated_s,rss_mb,step_ms_mean,cpu_ms_mean,cg_iterations_mean,max_strain,kinetic_j\n";
  }
  std::printf("soak: curtain in a %.1f m/s wind, script %s, %.1f simulated minutes, %ld windows of "
              "%.0f s, %d threads, self-collision %s\n", options.wind, options.script ? "repeated" : "off",
              options.minutes, windows, options.windowSeconds, world.threadCount(),
              options.selfCollision ? "on" : "off");
  std::printf("%8s %10s %10s %12s %10s %10s %10s %12s\n", "window", "sim s", "RSS MB", "step ms",
              "cpu ms", "PCG it", "strain", "kinetic J");
  Vec3Array pinRest, targets(grid.columns);
  for (Index vertex : settings.pinnedVertices) pinRest.push_back(model->restPositions()[vertex]);
  long frameIndex = 0;
  for (long window = 0; window < windows; ++window) {
    double milliseconds = 0, cpuMilliseconds = 0, strain = 0;
    long windowIterations = 0;
    for (long frame = 0; frame < framesPerWindow; ++frame) {
      if (options.script) {
        // The script's time, repeating every 10 s (it ends where it starts: open, sphere out).
        const Real end = std::fmod(Real(++frameIndex) * frameDt, 10.0);
        for (Index c = 0; c < grid.columns; ++c) targets[c] = CurtainScene::pinTarget(pinRest[c], end);
        (void)world.setPinTargets(cloth, targets);
        RigidMotion motionNow = motion(*world.collider(sphere).value());
        motionNow.linearVelocity = (CurtainScene::spherePosition(end) - motionNow.pose.position) / frameDt;
        (void)world.setColliderMotion(sphere, motionNow);
      }
      const double cpuStart = processCpuMilliseconds();
      const auto start = std::chrono::steady_clock::now();
      const StepStatus status = world.step(frameDt);
      milliseconds += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      cpuMilliseconds += processCpuMilliseconds() - cpuStart;
      windowIterations += world.stats().cgIterations;
      retried += hasFlag(status, StepStatus::RetriedWithSmallerStep);
      rolledBack += hasFlag(status, StepStatus::RolledBack);
      capped += hasFlag(status, StepStatus::SolverNotConverged);
      strain = std::max(strain, world.stats().maxStrain);
    }
    for (const Vec3& x : world.positions(cloth).value()) finite = finite && x.allFinite();
    if (options.checkIntersections) intersecting += counter.count(world.positions(cloth).value()) > 0;
    rss.push_back(residentMegabytes());
    stepMs.push_back(milliseconds / double(framesPerWindow));
    cpuMs.push_back(cpuMilliseconds / double(framesPerWindow));
    iterations.push_back(double(windowIterations) / double(framesPerWindow));
    const double simulated = world.time();
    std::printf("%8ld %10.0f %10.1f %12.3f %10.3f %10.1f %10.4f %12.4g\n", window + 1, simulated,
                rss.back(), stepMs.back(), cpuMs.back(), iterations.back(), strain,
                world.stats().kineticEnergy);
    std::fflush(stdout);
    if (csv) {
      csv << window + 1 << ',' << simulated << ',' << rss.back() << ',' << stepMs.back() << ','
          << cpuMs.back() << ',' << iterations.back() << ',' << strain << ',' << world.stats().kineticEnergy << '\n';
    }
  }

  // The first window holds the warm-up (first allocations, caches): growth counts from the end
  // of it. Drift compares the mean step time of the last 10 % of windows with the first 10 %.
  const std::size_t tenth = std::max<std::size_t>(1, rss.size() / 10);
  auto mean = [](auto begin, auto end) { return std::accumulate(begin, end, 0.0) / double(end - begin); };
  const double firstMs = mean(stepMs.begin(), stepMs.begin() + tenth);
  const double lastMs = mean(stepMs.end() - tenth, stepMs.end());
  const double growth = rss.back() - rss.front();
  const double drift = lastMs / firstMs;
  const long frames = windows * framesPerWindow;
  std::printf("\nmemory: %.1f MB after the first window, %.1f MB at the end: %s (%+.2f MB)\n",
              rss.front(), rss.back(), growth > 1.0 ? "GREW" : "did not grow", growth);
  std::printf("step time: first 10 %% %.3f ms, last 10 %% %.3f ms, ratio %.3f: %s\n", firstMs,
              lastMs, drift, std::abs(drift - 1) > 0.2 ? "DRIFTED (or the machine's load changed)"
                                                       : "no drift beyond 20 %");
  // CPU time per PCG iteration: the work per step changes with what the cloth does (the script
  // repeats, so it should not), and the CPU clock is the one other jobs disturb least.
  const double firstCpuPerIteration = mean(cpuMs.begin(), cpuMs.begin() + tenth) /
                                      std::max(1.0, mean(iterations.begin(), iterations.begin() + tenth));
  const double lastCpuPerIteration = mean(cpuMs.end() - tenth, cpuMs.end()) /
                                     std::max(1.0, mean(iterations.end() - tenth, iterations.end()));
  const double cpuDrift = lastCpuPerIteration / firstCpuPerIteration;
  std::printf("CPU time: first 10 %% %.3f ms/step, last 10 %% %.3f ms/step; per PCG iteration "
              "ratio %.3f: %s\n", mean(cpuMs.begin(), cpuMs.begin() + tenth),
              mean(cpuMs.end() - tenth, cpuMs.end()), cpuDrift,
              std::abs(cpuDrift - 1) > 0.1 ? "DRIFTED" : "no drift beyond 10 %");
  std::printf("PCG iterations per step: first 10 %% %.1f, last 10 %% %.1f\n",
              mean(iterations.begin(), iterations.begin() + tenth), mean(iterations.end() - tenth, iterations.end()));
  std::printf("frames %ld: retried %ld, rolled back %ld, solver cap %ld (%.3f %%), state %s",
              frames, retried, rolledBack, capped, 100.0 * double(capped) / double(frames),
              finite ? "finite" : "NOT FINITE");
  if (options.checkIntersections) std::printf(", windows ending with intersections %ld", intersecting);
  std::printf("\nstate hash %016llx\n", static_cast<unsigned long long>(world.stateHash()));
  return finite && rolledBack == 0 ? 0 : 1;
}

int runSteps(int threads) {
  // The full 10 s script, one implicit step per frame; error against the 1/600 s run each second.
  std::vector<Vec3Array> reference;
  for (int framesPerSecond : {600, 300, 120, 60, 30, 15}) {
    const Real frameDt = 1.0 / framesPerSecond;
    CurtainSettings settings;
    settings.solver.substeps = 1;
    settings.threadCount = threads;
    CurtainScene scene = CurtainScene::create(settings).value();
    World& world = scene.world();
    const ClothModel& model = scene.model();
    const Index columns = model.gridSize()[0], rows = model.gridSize()[1];
    Vec3Array rest, targets(columns), samples;
    for (Index c = 0; c < columns; ++c) rest.push_back(model.restPositions()[(rows - 1) * columns + c]);
    SelfIntersectionCounter counter =
        SelfIntersectionCounter::create(model.indices(), model.restPositions()).value();
    std::vector<Vec3Array> sampled;
    double strain = 0, milliseconds = 0;
    long capped = 0, rolledBack = 0, intersecting = 0;
    const int frames = 10 * framesPerSecond;
    for (int frame = 0; frame < frames; ++frame) {
      const Real end = (frame + 1) * frameDt;
      for (Index c = 0; c < columns; ++c) targets[c] = CurtainScene::pinTarget(rest[c], end);
      (void)world.setPinTargets(scene.cloth(), targets);
      RigidMotion sphere = motion(*world.collider(scene.sphere()).value());
      sphere.linearVelocity = (CurtainScene::spherePosition(end) - sphere.pose.position) / frameDt;
      (void)world.setColliderMotion(scene.sphere(), sphere);
      const StepStatus status = world.step(frameDt);
      milliseconds += world.stats().stepMs;
      capped += hasFlag(status, StepStatus::SolverNotConverged);
      rolledBack += hasFlag(status, StepStatus::RolledBack);
      strain = std::max(strain, world.stats().maxStrain);
      const bool onSixtieth = (frame + 1) % std::max(1, framesPerSecond / 60) == 0;
      if (onSixtieth) intersecting += counter.count(world.positions(scene.cloth()).value()) > 0;
      if ((frame + 1) % framesPerSecond == 0) {
        const std::span<const Vec3> x = world.positions(scene.cloth()).value();
        sampled.emplace_back(x.begin(), x.end());
      }
    }
    double sumSquares = 0, maxDistance = 0;
    std::size_t count = 0;
    if (reference.empty()) reference = sampled;
    for (std::size_t s = 0; s < sampled.size(); ++s) {
      for (std::size_t i = 0; i < sampled[s].size(); ++i) {
        const double d = (sampled[s][i] - reference[s][i]).norm();
        sumSquares += d * d;
        maxDistance = std::max(maxDistance, d);
        ++count;
      }
    }
    const double size = model.characteristicLength();
    std::printf("1/%-4d s: %5d frames, %.3f ms per frame, max strain %.4f, solver cap %.2f %%, "
                "rolled back %ld, frames with intersections %ld, error vs 1/600 s: RMS %.3e max %.3e\n",
                framesPerSecond, frames, milliseconds / frames, strain, 100.0 * capped / frames,
                rolledBack, intersecting, std::sqrt(sumSquares / double(count)) / size,
                maxDistance / size);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"weft-stress-soak: long stress runs: the hour-long curtain soak in wind, "
               "and the full curtain script at every frame step"};
  std::string scene = "soak";
  SoakOptions soak;
  app.add_option("--scene", scene, "soak | steps")->check(CLI::IsMember({"soak", "steps"}));
  app.add_option("--minutes", soak.minutes, "soak: simulated minutes (default 60)")->check(CLI::PositiveNumber);
  app.add_option("--window", soak.windowSeconds, "soak: simulated seconds per sample (default 30)")
      ->check(CLI::PositiveNumber);
  app.add_option("--wind", soak.wind, "soak: wind speed in m/s along +z (default 4)");
  app.add_option("--threads", soak.threads, "threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_option("--self-collision", soak.selfCollision, "soak: on|off (default on)")
      ->transform(CLI::Transformer(std::map<std::string, std::string>{{"on", "1"}, {"off", "0"}}));
  app.add_option("--script", soak.script, "soak: repeat the curtain's 10 s script, on|off (default on)")
      ->transform(CLI::Transformer(std::map<std::string, std::string>{{"on", "1"}, {"off", "0"}}));
  app.add_flag("--check-intersections", soak.checkIntersections,
               "soak: count intersecting triangle pairs at the end of every window");
  app.add_option("--csv", soak.csv, "soak: write one row per window to this file");
  CLI11_PARSE(app, argc, argv);
  return scene == "soak" ? runSoak(soak) : runSteps(soak.threads);
}
