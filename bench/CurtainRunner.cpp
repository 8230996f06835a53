#include "CurtainRunner.h"
#include "FrameChart.h"

#include <weft/threading/SampleStatistics.h>

#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/scenes/Curtain.h>
#include <weft/threading/Profiler.h>

#if WEFT_HAVE_RENDER
#include "RenderPipeline.h"

#include <weft/render/Png.h>
#endif

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <thread>
#include <vector>

namespace weft {
namespace {

using Clock = std::chrono::steady_clock;

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct FrameRecord {
  double simulationMs = 0;
  double renderMs = 0;
  double frameMs = 0;
  int cgIterations = 0;
  double cgResidual = 0;
  double assemblyMs = 0;
  double solveMs = 0;
  double maxStrain = 0;
  double kineticEnergy = 0;
  double potentialEnergy = 0;
  unsigned substeps = 0;
  StepStatus status = StepStatus::Ok;
  double engineMs = 0;          // step() as the engine measured it (what the budget is about)
  StepPlan plan;
  bool sleeping = false;
};

// Creates the folder a file will go into; false (with a message) when that is impossible.
bool prepareOutput(const std::string& path, bool isDirectory, std::ostream& out) {
  if (path.empty()) return true;
  const std::filesystem::path folder =
      isDirectory ? std::filesystem::path(path) : std::filesystem::path(path).parent_path();
  std::error_code error;
  if (!folder.empty()) std::filesystem::create_directories(folder, error);
  if (error) {
    out << "weft-curtain: cannot create the folder '" << folder.string() << "': "
        << error.message() << "; choose a writable location\n";
    return false;
  }
  return true;
}

// Frames worth a picture: settled, the sphere push (100), withdrawal, gathered, re-opening.
constexpr unsigned kCaptureFrames[] = {60, 100, 150, 330, 450};

std::string hex(std::uint64_t value) {
  std::ostringstream text;
  text << "0x" << std::hex << std::setw(16) << std::setfill('0') << value;
  return text.str();
}

}  // namespace

int runCurtain(const CurtainRunOptions& options, std::ostream& out) {
  CurtainSettings settings;
  settings.size = options.size;
  settings.solver.integrator = options.integrator;
  settings.threadCount = int(options.threads);
  settings.selfCollision = options.selfCollision;
  settings.skipUnneededStages = options.skips;
  settings.sleep = options.sleep;
  Result<ClothMaterial> fabric =
      options.stiffening ? stiffeningFabricPreset(options.fabric) : fabricPreset(options.fabric);
  if (!fabric.ok()) {
    out << "weft-curtain: --fabric: " << fabric.error().message << "\n";
    return 2;
  }
  settings.material = fabric.value();
  if (options.strainLimit >= 0) settings.material.strainLimit = options.strainLimit;
  Result<CurtainScene> created = CurtainScene::create(settings);
  if (!created.ok()) {
    out << "weft-curtain: " << created.error().message << "\n";
    return 2;
  }
  CurtainScene& scene = created.value();
  const unsigned hardwareThreads = std::max(1u, std::thread::hardware_concurrency());

  out << "Weft curtain benchmark (docs/curtain-benchmark.md)\n"
      << "  cloth      " << scene.model().gridSize()[0] << " x " << scene.model().gridSize()[1]
      << " vertices, " << scene.model().triangleCount() << " triangles (size x" << options.size
      << ")\n"
      << "  integrator " << integratorName(options.integrator) << ", "
      << scene.world().plannedSubsteps(scene.cloth(), CurtainScene::kFrameDt).value()
      << " substep(s) per 1/60 s frame\n"
      << "  frames     " << options.frames << " (" << options.frames * CurtainScene::kFrameDt
      << " s simulated)\n"
      << "  fabric     " << options.fabric << ", stretch "
      << (settings.material.stretchKneeStrain > 0 ? "biphasic (knee " + std::to_string(settings.material.stretchKneeStrain) + ")" : std::string("linear"))
      << ", strain limit " << settings.material.strainLimit << "\n";
  // Say plainly what this build does not do yet, rather than print numbers that look complete.
  out << "  threads    " << scene.world().threadCount() << " (machine has " << hardwareThreads
      << " cores)\n";
  out << "  contact    the sphere and the floor (colliders); self-collision "
      << (options.selfCollision ? "on" : "off") << "\n";
  for (const auto& [path, isDirectory] :
       {std::pair{options.summaryJson, false}, {options.frameCsv, false}, {options.trace, false},
        {options.captureDirectory, true}}) {
    if (!prepareOutput(path, isDirectory, out)) return 2;
  }
  const bool rendering = options.renderWidth > 0;
#if WEFT_HAVE_RENDER
  std::unique_ptr<RenderPipeline> pipeline;
  if (rendering) {
    RenderSettings renderSettings;
    renderSettings.width = int(options.renderWidth);
    renderSettings.height = int(options.renderHeight);
    renderSettings.camera.eye = Vec3(2.1, 1.6, 2.3);
    renderSettings.camera.target = Vec3(0.0, 1.2, 0.0);
    // The floor of the scene; the sphere is added per frame where it is.
    std::vector<ColliderPrimitive> colliders{PlanePrimitive{Vec3(0, 0, 0), Vec3(0, 1, 0), 3.0}};
    std::vector<unsigned> capture;
    if (!options.captureDirectory.empty()) capture.assign(std::begin(kCaptureFrames), std::end(kCaptureFrames));
    Result<std::unique_ptr<RenderPipeline>> started =
        RenderPipeline::start(renderSettings, colliders, capture, options.overlap);
    if (!started.ok()) {
      out << "weft-curtain: cannot render: " << started.error().message
          << "\n  (run with --render off to simulate only)\n";
      return 1;
    }
    pipeline = std::move(started).value();
    out << "  render     " << options.renderWidth << " x " << options.renderHeight << " on "
        << pipeline->rendererName() << ", "
        << (options.overlap ? "overlapping the next frame's simulation" : "in turn with simulation")
        << "\n";
  } else {
    out << "  render     off\n";
  }
#else
  if (rendering) {
    out << "  render     this binary was built without weft::render (WEFT_BUILD_RENDER=OFF); "
           "running --render off\n";
  } else {
    out << "  render     off\n";
  }
#endif
  if (!options.captureDirectory.empty() && !rendering) {
    out << "  capture    needs rendering; --capture ignored with --render off\n";
  }
  std::optional<SelfIntersectionCounter> intersectionCounter;
  if (options.checkIntersections) {
    Result<SelfIntersectionCounter> counter =
        SelfIntersectionCounter::create(scene.model().indices(), scene.model().restPositions());
    if (!counter.ok()) {
      out << "weft-curtain: " << counter.error().message << "\n";
      return 1;
    }
    intersectionCounter.emplace(std::move(counter).value());
    out << "  checking   intersecting triangle pairs every frame (not timed)\n";
  }
  if (options.budgetMs > 0) {
    out << "  budget     " << options.budgetMs
        << " ms per frame, planned by the engine (PCG tolerance down to "
        << StepBudget{}.loosestCgTolerance << ", at least " << StepBudget{}.fewestCgIterations
        << " iterations); misses from StepStats\n";
  }
  out << "  skips      " << (options.skips ? "on" : "off") << ", sleep "
      << (options.sleep ? "on" : "off") << "\n";
  out << std::flush;

  if (!options.trace.empty()) {
    Profiler::instance().registerThisThread("simulation");
    Profiler::instance().setEnabled(true);
  }
  std::vector<FrameRecord> records;
  records.reserve(options.frames);
  bool nonfinite = false;
  unsigned budgetMisses = 0;
  Index maxIntersections = 0, framesWithIntersections = 0;
  const auto runStart = Clock::now();
  for (unsigned frame = 0; frame < options.frames; ++frame) {
    const auto frameStart = Clock::now();
    StepBudget budget;
    budget.milliseconds = options.budgetMs;
    const StepStatus status = options.budgetMs > 0 ? scene.stepFrame(budget) : scene.stepFrame();
    FrameRecord record;
    record.simulationMs = millisecondsSince(frameStart);
#if WEFT_HAVE_RENDER
    // With overlap, this waits for the previous frame's drawing (which ran during this frame's
    // simulation) and then hands this frame over; without, it also waits for this frame.
    if (pipeline) {
      std::array<ColliderPrimitive, 1> sphere;
      std::span<const ColliderPrimitive> moving;
      if (!scene.sphere().isNull()) {
        sphere[0] = SpherePrimitive{motion(*scene.world().collider(scene.sphere()).value()).pose.position,
                                    CurtainScene::kSphereRadius * 0.98};
        moving = sphere;
      }
      pipeline->publish(frame + 1, scene.world().renderView(scene.cloth()).value(), moving);
    }
#endif
    record.frameMs = millisecondsSince(frameStart);
    const StepStats& stats = scene.world().stats();
    record.cgIterations = stats.cgIterations;
    record.cgResidual = stats.cgResidual;
    record.assemblyMs = stats.assemblyMs;
    record.solveMs = stats.solveMs;
    record.maxStrain = stats.maxStrain;
    record.kineticEnergy = stats.kineticEnergy;
    record.potentialEnergy = stats.potentialEnergy;
    record.substeps = stats.substeps;
    record.status = status;
    record.engineMs = stats.stepMs;
    record.plan = stats.plan;
    record.sleeping = stats.sleepingCloths > 0;
    nonfinite = nonfinite || hasFlag(status, StepStatus::RolledBack);
    if (intersectionCounter) {
      const Index pairs = intersectionCounter->count(scene.world().positions(scene.cloth()).value());
      maxIntersections = std::max(maxIntersections, pairs);
      framesWithIntersections += pairs > 0;
    }
    if (hasFlag(status, StepStatus::BudgetMissed)) ++budgetMisses;
    records.push_back(record);
    if (options.progress && (frame + 1) % 60 == 0) {
      out << "  t = " << std::setw(4) << std::fixed << std::setprecision(1)
          << (frame + 1) * CurtainScene::kFrameDt << " s  frame " << std::setw(4) << frame + 1
          << "  sim " << std::setprecision(2) << record.simulationMs << " ms  CG "
          << record.cgIterations << "  max strain " << std::setprecision(4) << record.maxStrain
          << "  status " << describe(status) << "\n"
          << std::flush;
    }
  }
#if WEFT_HAVE_RENDER
  if (pipeline) {
    pipeline->drain();
    if (!pipeline->error().empty()) {
      out << "weft-curtain: rendering failed: " << pipeline->error() << "\n";
      return 1;
    }
    for (const auto& [frame, timing] : pipeline->timings()) {
      if (frame >= 1 && frame <= records.size()) {
        records[frame - 1].renderMs = timing.renderMs + timing.readbackMs;
      }
    }
  }
#endif
  const double wallSeconds = millisecondsSince(runStart) / 1000.0;

  // Statistics skip frame 0: it pays for first-touch page faults and cold caches.
  auto column = [&](auto field) {
    std::vector<double> values;
    for (std::size_t k = records.size() > 1 ? 1 : 0; k < records.size(); ++k)
      values.push_back(double(field(records[k])));
    return values;
  };
  const std::vector<double> simulationMs = column([](const FrameRecord& r) { return r.simulationMs; });
  const std::vector<double> frameMs = column([](const FrameRecord& r) { return r.frameMs; });
  const std::vector<double> renderMs = column([](const FrameRecord& r) { return r.renderMs; });
  const std::vector<double> assemblyMs = column([](const FrameRecord& r) { return r.assemblyMs; });
  const std::vector<double> solveMs = column([](const FrameRecord& r) { return r.solveMs; });
  const std::vector<double> iterations = column([](const FrameRecord& r) { return r.cgIterations; });
  double maxStrain = 0, maxResidual = 0;
  unsigned unconverged = 0, unstable = 0, relaxedFrames = 0, sleepingFrames = 0;
  for (const FrameRecord& r : records) {
    maxStrain = std::max(maxStrain, r.maxStrain);
    maxResidual = std::max(maxResidual, r.cgResidual);
    relaxedFrames += !(r.plan == StepPlan{});
    sleepingFrames += r.sleeping;
    unconverged += hasFlag(r.status, StepStatus::SolverNotConverged);
    unstable += hasFlag(r.status, StepStatus::Unstable);
  }
  const double frameP50 = percentile(frameMs, 50), frameP99 = percentile(frameMs, 99);
  const std::uint64_t hash = scene.world().stateHash();

  out << std::fixed << std::setprecision(3) << "\nReport (" << records.size() << " frames, "
      << std::setprecision(2) << wallSeconds << " s wall)\n"
      << std::setprecision(3) << "  simulation ms  p50 " << percentile(simulationMs, 50) << "  p95 "
      << percentile(simulationMs, 95) << "  p99 " << percentile(simulationMs, 99) << "  max "
      << percentile(simulationMs, 100) << "\n"
      ;
  out << "    assembly ms  p50 " << percentile(assemblyMs, 50) << "   solve ms p50 "
      << percentile(solveMs, 50) << "\n";
  if (rendering) {
    out << "  render ms      p50 " << percentile(renderMs, 50) << "  p95 " << percentile(renderMs, 95) << "  p99 "
        << percentile(renderMs, 99) << "  (draw + read back "
        << options.renderWidth << " x " << options.renderHeight << ")\n";
  }
  out << "  frame ms       p50 " << frameP50 << "  p95 " << percentile(frameMs, 95) << "  p99 "
      << frameP99
      << (rendering ? (options.overlap ? "  (simulation overlapped with rendering)"
                                       : "  (simulation, then rendering)")
                    : "  (simulation only)")
      << "\n"
      << std::setprecision(1) << "  fps            p50 " << 1000.0 / frameP50 << "  p99 "
      << 1000.0 / frameP99 << "\n"
      << "  CG iterations  mean " << mean(iterations) << "  max " << percentile(iterations, 100)
      << "  (frames not converged: " << unconverged << ")\n"
      << std::setprecision(5) << "  max strain     " << maxStrain << "\n";
  // The largest strain of each phase of the script the run reached.
  out << "  max strain by phase";
  for (const CurtainPhase& phase : CurtainScene::phases()) {
    const std::size_t first = std::size_t(std::lround(phase.begin / CurtainScene::kFrameDt));
    const std::size_t last = std::min(records.size(), std::size_t(std::lround(phase.end / CurtainScene::kFrameDt)));
    if (first >= last) break;
    double largest = 0;
    for (std::size_t k = first; k < last; ++k) largest = std::max(largest, records[k].maxStrain);
    out << "  " << phase.name << " " << std::setprecision(4) << largest;
  }
  out << "\n"
      << "  unstable       " << unstable << " frame(s), non-finite: " << (nonfinite ? "yes" : "no")
      << "\n"
      << "  state hash     " << hex(hash) << "\n";
  if (options.budgetMs > 0) {
    out << "  budget misses  " << budgetMisses << " of " << records.size() << " frames (hit rate "
        << std::setprecision(1) << 100.0 * (1.0 - double(budgetMisses) / records.size())
        << " %), " << relaxedFrames << " frame(s) ran a relaxed plan\n"
        << std::setprecision(5) << "  accuracy       largest PCG residual " << maxResidual
        << ", largest strain " << maxStrain << "\n";
  }
  out << "  asleep         " << sleepingFrames << " frame(s)\n";
  if (intersectionCounter) {
    out << "  intersections  " << maxIntersections << " pairs at most, in "
        << framesWithIntersections << " frame(s)\n";
  }
  const double targetMs = 1.0;  // ≤ 1 ms simulation per frame at the median (the project's target)
  out << "  verdict        simulation median " << std::setprecision(3)
      << percentile(simulationMs, 50) << " ms vs the 1 ms target: "
      << (percentile(simulationMs, 50) <= targetMs ? "MET" : "NOT MET") << "\n";
  if (rendering) {
    const bool sixty = 1000.0 / frameP99 >= 60.0;
    out << "                 60 fps at p99 with rendering " << options.renderWidth << " x "
        << options.renderHeight << ": " << (sixty ? "MET" : "NOT MET") << " ("
        << std::setprecision(1) << 1000.0 / frameP99 << " fps)\n";
  } else {
    out << "                 60 fps with rendering: not measured (render off)\n";
  }
#if WEFT_HAVE_RENDER
  if (pipeline) {
    WEFT_PROFILE_ZONE("capture");
    for (const auto& [frame, image] : pipeline->captured()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04u.png", frame);
      const std::string path = (std::filesystem::path(options.captureDirectory) / name).string();
      Status written = writePng(path, image);
      if (!written.ok()) {
        out << "weft-curtain: " << written.error().message << "\n";
        return 1;
      }
      out << "  picture        " << path << "\n";
    }
  }
#endif
  if (!options.summaryJson.empty()) {
    nlohmann::json summary = {
        {"frames", records.size()},
        {"triangles", scene.model().triangleCount()},
        {"size", options.size},
        {"integrator", integratorName(options.integrator)},
        {"threads", scene.world().threadCount()},
        {"sim_ms_p50", percentile(simulationMs, 50)},
        {"sim_ms_p95", percentile(simulationMs, 95)},
        {"sim_ms_p99", percentile(simulationMs, 99)},
        {"render_ms_p50", rendering ? nlohmann::json(percentile(renderMs, 50)) : nlohmann::json(nullptr)},
        {"render_ms_p99", rendering ? nlohmann::json(percentile(renderMs, 99)) : nlohmann::json(nullptr)},
        {"frame_ms_p50", frameP50},
        {"frame_ms_p99", frameP99},
        {"fps_p50", 1000.0 / frameP50},
        {"fps_p99", 1000.0 / frameP99},
        {"cg_iterations_mean", mean(iterations)},
        {"max_strain", maxStrain},
        {"intersections", intersectionCounter ? std::int64_t(maxIntersections) : std::int64_t(-1)},
        {"frames_with_intersections",
         intersectionCounter ? std::int64_t(framesWithIntersections) : std::int64_t(-1)},
        {"nonfinite", nonfinite},
        {"budget_misses", budgetMisses},
        {"budget_ms", options.budgetMs},
        {"budget_relaxed_frames", relaxedFrames},
        {"cg_residual_max", maxResidual},
        {"sleeping_frames", sleepingFrames},
        {"skips", options.skips},
        {"sleep", options.sleep},
        {"state_hash", hex(hash)},
        {"render", rendering ? std::to_string(options.renderWidth) + "x" + std::to_string(options.renderHeight) : std::string("off")},
        {"overlap", rendering && options.overlap},
        {"self_collision", options.selfCollision},
    };
    std::ofstream file(options.summaryJson);
    if (!file) {
      out << "weft-curtain: cannot write the summary to '" << options.summaryJson
          << "'; check that the directory exists and is writable\n";
      return 1;
    }
    file << summary.dump(2) << "\n";
    out << "  summary        " << options.summaryJson << "\n";
  }
  if (!options.frameCsv.empty()) {
    std::ofstream file(options.frameCsv);
    if (!file) {
      out << "weft-curtain: cannot write the CSV to '" << options.frameCsv
          << "'; check that the directory exists and is writable\n";
      return 1;
    }
    file << "frame,sim_ms,assembly_ms,solve_ms,render_ms,frame_ms,substeps,cg_iterations,"
            "cg_residual,max_strain,kinetic_energy,potential_energy,status,engine_ms,"
            "plan_substeps,plan_cg_tolerance,plan_cg_max_iterations,sleeping\n";
    file << std::setprecision(9);
    for (std::size_t k = 0; k < records.size(); ++k) {
      const FrameRecord& r = records[k];
      file << k + 1 << ',' << r.simulationMs << ',' << r.assemblyMs << ',' << r.solveMs << ','
           << r.renderMs << ',' << r.frameMs << ','
           << r.substeps << ',' << r.cgIterations << ',' << r.cgResidual << ',' << r.maxStrain
           << ',' << r.kineticEnergy << ',' << r.potentialEnergy << ',' << describe(r.status)
           << ',' << r.engineMs << ',' << r.plan.substeps << ',' << r.plan.cgTolerance << ','
           << r.plan.cgMaxIterations << ',' << r.sleeping << '\n';
    }
    file.close();
    out << "  per-frame CSV  " << options.frameCsv << "\n";
    // The chart of the CSV, beside it: frame times against the script's phases.
    FrameChartSettings chart;
    const std::filesystem::path csvPath(options.frameCsv);
    chart.csvPath = options.frameCsv;
    chart.pngPath = std::filesystem::path(csvPath).replace_extension(".png").string();
    chart.scriptPath = std::filesystem::path(csvPath).replace_extension(".gp").string();
    std::ostringstream title;
    title << "Weft curtain x" << options.size << ": time per frame (" << scene.world().threadCount()
          << " thread(s), " << (rendering ? "rendering " + std::to_string(options.renderWidth) + "x" +
                                               std::to_string(options.renderHeight)
                                          : std::string("render off"))
          << std::fixed << std::setprecision(2) << "; simulation p50 " << percentile(simulationMs, 50)
          << " ms, p99 " << percentile(simulationMs, 99) << " ms)";
    chart.title = title.str();
    chart.frames = unsigned(records.size());
    chart.rendering = rendering;
    chart.budgetMs = options.budgetMs;
    chart.targetMs = targetMs;
    for (const CurtainPhase& phase : CurtainScene::phases()) {
      const double begin = phase.begin / CurtainScene::kFrameDt, end = phase.end / CurtainScene::kFrameDt;
      if (begin >= double(records.size())) break;
      chart.phases.push_back({begin, std::min(end, double(records.size())), phase.name});
    }
    const FrameChartOutcome charted = writeFrameChart(chart);
    if (charted.written) {
      out << "  chart          " << chart.pngPath << " (gnuplot script " << chart.scriptPath << ")\n";
    } else if (charted.skipped) {
      out << "  chart          skipped: " << charted.message << "\n";
    } else {
      out << "weft-curtain: chart: " << charted.message << "\n";
      return 1;
    }
  }
  if (!options.trace.empty()) {
    Profiler::instance().setEnabled(false);
    const TraceWriteResult written = Profiler::instance().writeChromeTrace(options.trace);
    if (!written) {
      out << "weft-curtain: " << written.error << "\n";
      return 1;
    }
    out << "  trace          " << options.trace << " (" << written.eventCount << " zones"
        << (written.droppedCount ? ", " + std::to_string(written.droppedCount) + " dropped" : "")
        << "; open in Perfetto or chrome://tracing)\n";
  }
  return nonfinite ? 1 : 0;
}

}  // namespace weft
