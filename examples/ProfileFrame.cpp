// ProfileFrame: where a frame's time goes. A curtain-like sheet is pinned along its top edge and a
// sphere pushes into it; the profiler records every frame, and the program prints, for the frame
// that cost the most, the engine's own counters (World::stats()) beside the profiler's zone
// totals (Profiler::frameTotals()), then writes the whole run as a Chrome trace to open in
// Perfetto (ui.perfetto.dev) or chrome://tracing. docs/profiling.md explains what to look for.
//
//   weft-example-profile-frame [frames = 90] [trace file = profile-frame-trace.json]
#include <weft/Weft.h>
#include <weft/threading/Profiler.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace {

constexpr double kFrameDt = 1.0 / 60.0;  // s

int parseFrames(int argc, char** argv) {
  if (argc < 2) return 90;
  int frames = 0;
  const char* end = argv[1] + std::strlen(argv[1]);
  const auto [ptr, ec] = std::from_chars(argv[1], end, frames);
  if (ec != std::errc{} || ptr != end || frames <= 0) return -1;
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = parseFrames(argc, argv);
  if (frames < 0) {
    std::fprintf(stderr, "usage: %s [frames > 0, default 90] [trace file]\n", argv[0]);
    return 2;
  }
  const std::string tracePath = argc > 2 ? argv[2] : "profile-frame-trace.json";

  // A 1.5 m × 1 m sheet hanging in the plane z = 0 from its top row (the curtain's spacing).
  weft::GridSettings grid;
  grid.columns = 31;
  grid.rows = 21;
  grid.width = 1.5;
  grid.height = 1.0;
  grid.origin = weft::Vec3(-0.75, 0.5, 0.0);
  auto model = weft::ClothModel::grid(grid);
  if (!model) {
    std::fprintf(stderr, "profile-frame: %s\n", model.error().message.c_str());
    return 1;
  }
  auto shared = std::make_shared<const weft::ClothModel>(std::move(model).value());
  weft::ClothSettings settings;
  settings.material = weft::cottonFabric();
  for (weft::Index column = 0; column < grid.columns; ++column) {
    settings.pinnedVertices.push_back((grid.rows - 1) * grid.columns + column);
  }
  weft::World world;
  auto cloth = world.createCloth(shared, settings);
  if (!cloth) {
    std::fprintf(stderr, "profile-frame: %s\n", cloth.error().message.c_str());
    return 1;
  }
  // A sphere behind the sheet, moving through it at 0.5 m/s.
  weft::RigidMotion start;
  start.pose.position = weft::Vec3(0.2, 1.0, -0.4);
  start.linearVelocity = weft::Vec3(0.0, 0.0, 0.5);
  auto sphere = weft::Sphere::create(0.2, start);
  if (!sphere || !world.addCollider(sphere.value())) {
    std::fprintf(stderr, "profile-frame: cannot add the sphere\n");
    return 1;
  }

  // Record from here on; naming this thread labels its row in the trace.
  weft::Profiler& profiler = weft::Profiler::instance();
  profiler.registerThisThread("main");
  profiler.setEnabled(true);
  weft::StepStats slowest;
  for (int frame = 0; frame < frames; ++frame) {
    const weft::StepStatus status = world.step(kFrameDt);
    if (weft::hasFlag(status, weft::StepStatus::RolledBack)) {
      std::fprintf(stderr, "profile-frame: frame %d: %s\n", frame + 1,
                   weft::describe(status).c_str());
      return 1;
    }
    // The first frame pays for first touches of memory: leave it out, as the benchmarks do.
    if (frame > 0 && world.stats().stepMs > slowest.stepMs) slowest = world.stats();
  }
  profiler.setEnabled(false);

  std::printf("profile-frame: %d frames of a %u-triangle sheet on %d thread(s); slowest frame %llu\n",
              frames, static_cast<unsigned>(shared->triangleCount()), world.threadCount(),
              static_cast<unsigned long long>(slowest.frame));
  std::printf("  stats     step %.3f ms (assembly %.3f, solve %.3f), %d substep(s), %d CG "
              "iterations, %u collider contacts, %u self-contacts, max strain %.4f, status %s\n",
              slowest.stepMs, slowest.assemblyMs, slowest.solveMs, static_cast<int>(slowest.substeps),
              slowest.cgIterations, static_cast<unsigned>(slowest.contacts),
              static_cast<unsigned>(slowest.selfContacts), slowest.maxStrain,
              weft::describe(slowest.status).c_str());
  // Zone totals add up every thread: a parallel stage counts its CPU time, not its wall time.
  std::printf("  zones     (ms summed over threads, count)\n");
  for (const weft::ZoneTotal& zone : profiler.frameTotals(slowest.frame)) {
    std::printf("    %-26s %8.3f  x%u\n", zone.name.c_str(), zone.totalMs, zone.count);
  }
  const weft::TraceWriteResult written = profiler.writeChromeTrace(tracePath);
  if (!written) {
    std::fprintf(stderr, "profile-frame: %s\n", written.error.c_str());
    return 1;
  }
  std::printf("profile-frame: ok, trace %s (%zu zones, %zu dropped); open it in ui.perfetto.dev\n",
              tracePath.c_str(), written.eventCount, written.droppedCount);
  return 0;
}
