// weft-vs-bullet: the curtain in Weft and in Bullet's soft body, in one process,
// measured by one ruler (ClothMeter), with a markdown table of time, strain, intersections and
// blow-ups and the ratios Weft / Bullet. Settings of each engine and why: bench/peers/README.md.
//
// For every size and for self-collision off and on, Weft runs first (on each requested thread
// count); its max strain, over the whole run and over the frames before the rod gathers, is the
// target. Without self-collision Bullet then runs at its default position iterations (1) and at
// more and more (× the iteration factor) until each of its two max strains is at or below Weft's
// or stops improving (less than kStallFraction better than the previous point), or the count
// passes --max-iterations. With self-collision, whose clusters are costly, Bullet runs at its
// default and at the point where that sweep ended. The verdicts compare Weft with the first
// Bullet point that reached Weft's strain, or with Bullet's least-strained point when none did.
#include "BulletCurtain.h"
#include "ClothMeter.h"

#include <weft/threading/SampleStatistics.h>

#include <weft/scenes/Curtain.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace weft {
namespace {

using Clock = std::chrono::steady_clock;

constexpr double kStallFraction = 0.03;  // a point less than 3 % better than the last: stalled
constexpr double kSpeedTarget = 5.0;     // the target: Weft at least 5× faster at equal strain

struct Options {
  std::vector<unsigned> sizes{1, 4, 16};
  unsigned frames = 600;
  unsigned largeFrames = 0;  // frames from size 16 on (0: --frames)
  std::vector<unsigned> weftThreads{1, 2};
  std::string selfCollision = "both";
  std::vector<int> iterations;  // explicit Bullet iteration counts (empty: the adaptive sweep)
  int iterationFactor = 2;
  int largeIterationFactor = 4;  // from size 16 on, where each Bullet run is long
  int maxIterations = 128;
  unsigned bulletSelfCollisionMaxSize = 4;  // Bullet's per-face clusters cost O(faces²) memory
  bool allThreadsWithoutSelfCollision = false;
  BulletCurtainSettings bullet;
  std::string json, markdown;
  bool quiet = false;
};

struct RunRecord {
  Index size = 1;
  std::string engine;  // "Weft" or "Bullet"
  bool selfCollision = false;
  unsigned threads = 1;
  int iterations = 0;  // Bullet's piterations
  int substeps = 0;    // Bullet steps per frame (Weft plans its own: reported in `settings`)
  std::string settings;
  double msP50 = 0, msP99 = 0, wallSeconds = 0;
  ClothMeasurements measured;
  double engineMaxStrain = -1;  // Weft's own StepStats::maxStrain, as a cross-check
  Index rolledBackFrames = 0;
  bool failed = false;          // could not be built
  std::string error;
};

// A run stops at its first blow-up: its times cover the frames before it.
std::string blowUp(const ClothMeasurements& m) {
  if (m.firstNonFiniteFrame >= 0) return "NaN at frame " + std::to_string(m.firstNonFiniteFrame) + " (run stopped)";
  if (m.firstExplodedFrame >= 0) return "exploded at frame " + std::to_string(m.firstExplodedFrame) + " (run stopped)";
  return "no";
}
bool blewUp(const ClothMeasurements& m) { return m.firstNonFiniteFrame >= 0 || m.firstExplodedFrame >= 0; }

// Frame times without frame 0, which pays for first touches of memory in both engines.
void summariseTimes(const std::vector<double>& frameMs, RunRecord& record) {
  std::vector<double> timed(frameMs.size() > 1 ? frameMs.begin() + 1 : frameMs.begin(), frameMs.end());
  record.msP50 = percentile(timed, 50);
  record.msP99 = percentile(timed, 99);
}

RunRecord runWeft(Index size, unsigned threads, bool selfCollision, unsigned frames) {
  RunRecord record;
  record.size = size;
  record.engine = "Weft";
  record.selfCollision = selfCollision;
  record.threads = threads;
  CurtainSettings settings;
  settings.size = size;
  settings.threadCount = int(threads);
  settings.selfCollision = selfCollision;
  Result<CurtainScene> created = CurtainScene::create(settings);
  if (!created.ok()) {
    record.failed = true;
    record.error = created.error().message;
    return record;
  }
  CurtainScene& scene = created.value();
  Result<ClothMeter> meter = ClothMeter::create(scene.model().indices(), scene.model().restPositions());
  if (!meter.ok()) {
    record.failed = true;
    record.error = meter.error().message;
    return record;
  }
  std::ostringstream text;
  text << integratorName(settings.solver.integrator) << ", "
       << scene.world().plannedSubsteps(scene.cloth(), CurtainScene::kFrameDt).value() << " substep(s), "
       << scene.world().threadCount() << " thread(s)";
  record.settings = text.str();
  std::vector<double> frameMs;
  frameMs.reserve(frames);
  double engineMax = 0;
  const auto runStart = Clock::now();
  for (unsigned frame = 0; frame < frames; ++frame) {
    const auto start = Clock::now();
    const StepStatus status = scene.stepFrame();
    frameMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    record.rolledBackFrames += hasFlag(status, StepStatus::RolledBack);
    engineMax = std::max(engineMax, double(scene.world().stats().maxStrain));
    meter.value().measure(scene.world().positions(scene.cloth()).value());
    if (blewUp(meter.value().result())) break;  // what follows would time a wreck
  }
  record.wallSeconds = std::chrono::duration<double>(Clock::now() - runStart).count();
  summariseTimes(frameMs, record);
  record.measured = meter.value().result();
  record.engineMaxStrain = engineMax;
  return record;
}

RunRecord runBullet(BulletCurtainSettings settings, unsigned frames) {
  RunRecord record;
  record.size = settings.size;
  record.engine = "Bullet";
  record.selfCollision = settings.selfCollision;
  record.threads = 1;
  record.iterations = settings.positionIterations;
  record.substeps = settings.substeps;
  Result<std::unique_ptr<BulletCurtain>> created = BulletCurtain::create(settings);
  if (!created.ok()) {
    record.failed = true;
    record.error = created.error().message;
    return record;
  }
  BulletCurtain& curtain = *created.value();
  Result<ClothMeter> meter = ClothMeter::create(curtain.indices(), curtain.restPositions());
  if (!meter.ok()) {
    record.failed = true;
    record.error = meter.error().message;
    return record;
  }
  std::ostringstream text;
  text << "piterations " << settings.positionIterations << ", " << settings.substeps << " step(s)/frame"
       << (settings.selfCollision ? ", clusters" : "");
  record.settings = text.str();
  std::vector<double> frameMs;
  frameMs.reserve(frames);
  Vec3Array positions;
  const auto runStart = Clock::now();
  for (unsigned frame = 0; frame < frames; ++frame) {
    const auto start = Clock::now();
    curtain.stepFrame();
    frameMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    curtain.readPositions(positions);
    meter.value().measure(positions);
    if (blewUp(meter.value().result())) break;  // what follows would time a wreck
  }
  record.wallSeconds = std::chrono::duration<double>(Clock::now() - runStart).count();
  summariseTimes(frameMs, record);
  record.measured = meter.value().result();
  return record;
}

std::string fixed(double value, int digits) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(digits) << value;
  return text.str();
}

// Strains past the explosion threshold say only that: their digits are noise.
std::string strainText(double strain, int digits) {
  return strain > 10 * ClothMeter::kExplodedStrain ? std::string("> ") + fixed(10 * ClothMeter::kExplodedStrain, 0)
                                                   : fixed(strain, digits);
}

std::string progressLine(const RunRecord& r) {
  if (r.failed) return r.engine + " failed: " + r.error;
  std::ostringstream text;
  text << "  x" << r.size << " " << std::setw(6) << r.engine << " self " << (r.selfCollision ? "on " : "off")
       << "  " << std::setw(38) << std::left << r.settings << std::right << "  p50 " << fixed(r.msP50, 2)
       << " ms  p99 " << fixed(r.msP99, 2) << " ms  max strain " << strainText(r.measured.maxStrain, 4)
       << " (before gather " << strainText(r.measured.maxStrainBeforeGather, 4) << ")"
       << " (frame " << r.measured.maxStrainFrame << ", edge " << r.measured.maxStrainEdge[0] << "-"
       << r.measured.maxStrainEdge[1] << ")  mean " << strainText(r.measured.meanStrain, 5) << "  pairs " << r.measured.maxIntersections << "/"
       << r.measured.framesWithIntersections << "  " << blowUp(r.measured) << "  (" << fixed(r.wallSeconds, 1)
       << " s)";
  return text.str();
}

// The Weft run of a size, self-collision mode and thread count, if there is one.
const RunRecord* findWeft(const std::vector<RunRecord>& runs, Index size, bool self, unsigned threads) {
  for (const RunRecord& r : runs) {
    if (r.engine == "Weft" && r.size == size && r.selfCollision == self && r.threads == threads && !r.failed) return &r;
  }
  return nullptr;
}

std::string ratio(double numerator, double denominator, int digits = 3) {
  if (!(denominator > 0)) return "–";
  return fixed(numerator / denominator, digits);
}

std::string makeTable(const std::vector<RunRecord>& runs, const Options& options) {
  const unsigned firstThreads = options.weftThreads.front();
  const unsigned secondThreads = options.weftThreads.size() > 1 ? options.weftThreads[1] : 0;
  std::ostringstream out;
  out << "| size | engine | self-collision | settings | frames | ms/frame p50 | ms/frame p99 | max strain | max strain, frames 1-240 | mean strain "
         "| intersecting pairs (max / frames) | NaN / explosion | Weft " << firstThreads << "T / Bullet ms";
  if (secondThreads) out << " | Weft " << secondThreads << "T / Bullet ms";
  out << " | Weft / Bullet max strain |\n|---|---|---|---|--:|--:|--:|--:|--:|--:|--:|---|--:|";
  if (secondThreads) out << "--:|";
  out << "--:|\n";
  for (const RunRecord& r : runs) {
    if (r.failed) {
      out << "| x" << r.size << " | " << r.engine << " | " << (r.selfCollision ? "on" : "off")
          << " | failed: " << r.error << " |||||||||||\n";
      continue;
    }
    out << "| x" << r.size << " | " << r.engine << " | " << (r.selfCollision ? "on" : "off") << " | " << r.settings
        << " | " << r.measured.frames << " | " << fixed(r.msP50, 2) << " | " << fixed(r.msP99, 2) << " | " << strainText(r.measured.maxStrain, 4) << " | "
        << strainText(r.measured.maxStrainBeforeGather, 4) << " | " << strainText(r.measured.meanStrain, 5) << " | " << r.measured.maxIntersections << " / "
        << r.measured.framesWithIntersections << " | " << blowUp(r.measured);
    const RunRecord* weft1 = findWeft(runs, r.size, r.selfCollision, firstThreads);
    const RunRecord* weft2 = secondThreads ? findWeft(runs, r.size, r.selfCollision, secondThreads) : nullptr;
    if (r.engine == "Bullet" && weft1) {
      out << " | " << ratio(weft1->msP50, r.msP50);
      if (secondThreads) out << " | " << (weft2 ? ratio(weft2->msP50, r.msP50) : "–");
      out << " | " << ratio(weft1->measured.maxStrain, r.measured.maxStrain);
    } else {
      out << " | ";
      if (secondThreads) out << " | ";
      out << " | ";
    }
    out << " |\n";
  }
  return out.str();
}

// Per size, mode and strain measure: Weft against the cheapest Bullet point at Weft's strain, or
// against Bullet's least-strained point when it never gets there.
std::string makeVerdicts(const std::vector<RunRecord>& runs, const Options& options, nlohmann::json& verdicts) {
  struct Measure {
    const char* name;
    double (*strain)(const RunRecord&);
  };
  const Measure measures[] = {
      {"max strain over the whole run", [](const RunRecord& r) { return r.measured.maxStrain; }},
      {"max strain before the gather (frames 1-240)",
       [](const RunRecord& r) { return r.measured.maxStrainBeforeGather; }},
  };
  std::ostringstream out;
  for (unsigned size : options.sizes) {
    for (bool self : {false, true}) {
      const RunRecord* weft1 = findWeft(runs, size, self, options.weftThreads.front());
      if (!weft1) continue;
      for (const Measure& measure : measures) {
        const double weftStrain = measure.strain(*weft1);
        const RunRecord* match = nullptr;
        const RunRecord* best = nullptr;
        for (const RunRecord& r : runs) {
          if (r.engine != "Bullet" || r.size != size || r.selfCollision != self || r.failed || blewUp(r.measured)) continue;
          if (!match && measure.strain(r) <= weftStrain) match = &r;
          if (!best || measure.strain(r) < measure.strain(*best)) best = &r;
        }
        const RunRecord* compared = match ? match : best;
        if (!compared) {
          out << "- x" << size << ", self-collision " << (self ? "on" : "off") << ", " << measure.name << ": ";
          std::string frames;
          for (const RunRecord& r : runs) {
            if (r.engine == "Bullet" && r.size == size && r.selfCollision == self && !r.failed) {
              frames += (frames.empty() ? "" : ", ") +
                        std::to_string(std::max(r.measured.firstNonFiniteFrame, r.measured.firstExplodedFrame));
            }
          }
          out << (frames.empty() ? "Bullet was not run" : "every Bullet point blew up (at frames " + frames + ")")
              << "; Weft ran all " << weft1->measured.frames << " frames at " << fixed(weftStrain, 4) << " with "
              << weft1->measured.maxIntersections << " intersecting pairs at most";
          // Weft with self-collision against Bullet's cheapest stable point without it.
          const RunRecord* plain = nullptr;
          for (const RunRecord& r : runs) {
            if (r.engine != "Bullet" || r.size != size || r.selfCollision || r.failed || blewUp(r.measured)) continue;
            if (measure.strain(r) <= weftStrain) {
              plain = &r;
              break;
            }
            if (!plain || measure.strain(r) < measure.strain(*plain)) plain = &r;
          }
          nlohmann::json verdict = {{"size", size}, {"self_collision", self}, {"measure", measure.name},
                                    {"weft_strain", weftStrain}, {"bullet_stable_point", false}};
          if (plain) {
            out << ". Against Bullet without self-collision at " << plain->settings << " ("
                << fixed(measure.strain(*plain), 4) << ", " << fixed(plain->msP50, 2) << " ms/frame, "
                << plain->measured.maxIntersections << " intersecting pairs at most), Weft is";
            for (std::size_t t = 0; t < options.weftThreads.size(); ++t) {
              if (const RunRecord* weftN = findWeft(runs, size, self, options.weftThreads[t])) {
                const double speed = plain->msP50 / weftN->msP50;
                out << (t ? "," : "") << " " << fixed(speed, 2) << "x as fast on " << weftN->threads << " thread(s)";
                verdict["speedup_vs_bullet_without_self_collision_threads_" + std::to_string(weftN->threads)] = speed;
              }
            }
          }
          out << "\n";
          verdicts.push_back(verdict);
          continue;
        }
        out << "- x" << size << ", self-collision " << (self ? "on" : "off") << ", " << measure.name << ": ";
        if (match) {
          out << "Bullet reaches Weft's " << fixed(weftStrain, 4) << " at " << compared->settings << " ("
              << fixed(measure.strain(*compared), 4) << ", " << fixed(compared->msP50, 2) << " ms/frame)";
        } else {
          out << "Bullet never reaches Weft's " << fixed(weftStrain, 4) << "; its least-strained point is "
              << compared->settings << " (" << fixed(measure.strain(*compared), 4) << ", "
              << fixed(compared->msP50, 2) << " ms/frame)";
        }
        nlohmann::json verdict = {{"size", size},
                                  {"self_collision", self},
                                  {"measure", measure.name},
                                  {"weft_strain", weftStrain},
                                  {"bullet_strain", measure.strain(*compared)},
                                  {"bullet_reaches_weft_strain", match != nullptr},
                                  {"bullet_iterations", compared->iterations},
                                  {"bullet_substeps", compared->substeps}};
        double bestSpeed = 0;
        out << ". Weft is";
        for (std::size_t t = 0; t < options.weftThreads.size(); ++t) {
          if (const RunRecord* weftN = findWeft(runs, size, self, options.weftThreads[t])) {
            const double speed = compared->msP50 / weftN->msP50;
            bestSpeed = std::max(bestSpeed, speed);
            out << (t ? "," : "") << " " << fixed(speed, 2) << "x as fast on " << weftN->threads << " thread(s)";
            verdict["speedup_weft_threads_" + std::to_string(weftN->threads)] = speed;
          }
        }
        // Strain is matched by construction: Bullet's point is at or below Weft's strain when it
        // reaches it, and above it (Weft better) when it never does.
        const bool fastOk = bestSpeed >= kSpeedTarget;
        const bool penetrationOk = weft1->measured.maxIntersections == 0;
        out << ". Intersecting pairs (most in a frame): Weft " << weft1->measured.maxIntersections << ", Bullet "
            << compared->measured.maxIntersections << ". Target (>= " << fixed(kSpeedTarget, 0)
            << "x as fast at equal or lower strain, zero intersections where Bullet has some): "
            << ((fastOk && penetrationOk) ? "MET" : "NOT MET") << (fastOk ? "" : " (speed)")
            << (penetrationOk ? "" : " (intersections)") << "\n";
        verdict["target_met"] = fastOk && penetrationOk;
        verdicts.push_back(verdict);
      }
    }
  }
  return out.str();
}

nlohmann::json toJson(const RunRecord& r) {
  return {{"size", r.size},
          {"engine", r.engine},
          {"self_collision", r.selfCollision},
          {"threads", r.threads},
          {"bullet_iterations", r.iterations},
          {"bullet_substeps", r.substeps},
          {"settings", r.settings},
          {"failed", r.failed},
          {"error", r.error},
          {"ms_p50", r.msP50},
          {"ms_p99", r.msP99},
          {"wall_seconds", r.wallSeconds},
          {"max_strain", r.measured.maxStrain},
          {"mean_strain", r.measured.meanStrain},
          {"max_strain_before_gather", r.measured.maxStrainBeforeGather},
          {"max_strain_frame", r.measured.maxStrainFrame},
          {"max_strain_edge", r.measured.maxStrainEdge},
          {"engine_max_strain", r.engineMaxStrain},
          {"max_intersecting_pairs", r.measured.maxIntersections},
          {"frames_with_intersections", r.measured.framesWithIntersections},
          {"first_nonfinite_frame", r.measured.firstNonFiniteFrame},
          {"first_exploded_frame", r.measured.firstExplodedFrame},
          {"rolled_back_frames", r.rolledBackFrames},
          {"frames", r.measured.frames}};
}

RunRecord fromJson(const nlohmann::json& j) {
  RunRecord r;
  r.size = j.at("size").get<Index>();
  r.engine = j.at("engine").get<std::string>();
  r.selfCollision = j.at("self_collision").get<bool>();
  r.threads = j.at("threads").get<unsigned>();
  r.iterations = j.at("bullet_iterations").get<int>();
  r.substeps = j.at("bullet_substeps").get<int>();
  r.settings = j.at("settings").get<std::string>();
  r.failed = j.at("failed").get<bool>();
  r.error = j.at("error").get<std::string>();
  r.msP50 = j.at("ms_p50").get<double>();
  r.msP99 = j.at("ms_p99").get<double>();
  r.wallSeconds = j.at("wall_seconds").get<double>();
  r.measured.maxStrain = j.at("max_strain").get<double>();
  r.measured.meanStrain = j.at("mean_strain").get<double>();
  r.measured.maxStrainBeforeGather = j.at("max_strain_before_gather").get<double>();
  r.measured.maxStrainFrame = j.at("max_strain_frame").get<int>();
  r.measured.maxStrainEdge = j.at("max_strain_edge").get<std::array<Index, 2>>();
  r.measured.maxIntersections = j.at("max_intersecting_pairs").get<Index>();
  r.measured.framesWithIntersections = j.at("frames_with_intersections").get<Index>();
  r.measured.firstNonFiniteFrame = j.at("first_nonfinite_frame").get<int>();
  r.measured.firstExplodedFrame = j.at("first_exploded_frame").get<int>();
  r.measured.frames = j.at("frames").get<Index>();
  r.engineMaxStrain = j.at("engine_max_strain").get<double>();
  r.rolledBackFrames = j.at("rolled_back_frames").get<Index>();
  return r;
}

std::string makeReport(const std::vector<RunRecord>& runs, const Options& options, nlohmann::json& verdicts) {
  std::ostringstream report;
  report << "\n## Weft vs Bullet: the curtain\n\n" << makeTable(runs, options);
  report << "\n" << makeVerdicts(runs, options, verdicts);
  report << "\nStrain: max(0, l / l_rest - 1) over the triangle-mesh edges (stretch only, as Weft's "
            "StepStats::maxStrain); max over all frames, mean over frames of the per-frame edge mean. "
            "Intersecting pairs: Weft's SelfIntersectionCounter on each engine's own triangles, every frame. "
            "Times: one frame's step, p50 and p99 over all frames but the first. Ratios < 1 mean Weft takes less time. "
            "The machine may have been shared while this ran: compare ratios within one run.\n";
  return report.str();
}

// Prints the table and verdicts of a JSON file an earlier run wrote, without running anything.
int reportFrom(const std::string& path, Options options) {
  std::ifstream file(path);
  if (!file) {
    std::cerr << "weft-vs-bullet: cannot read '" << path << "'; give a file written by --json\n";
    return 2;
  }
  const nlohmann::json document = nlohmann::json::parse(file, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded() || !document.contains("runs")) {
    std::cerr << "weft-vs-bullet: '" << path << "' is not a --json file of weft-vs-bullet\n";
    return 2;
  }
  std::vector<RunRecord> runs;
  options.sizes.clear();
  options.weftThreads.clear();
  for (const nlohmann::json& entry : document["runs"]) {
    runs.push_back(fromJson(entry));
    const RunRecord& r = runs.back();
    if (std::find(options.sizes.begin(), options.sizes.end(), r.size) == options.sizes.end()) options.sizes.push_back(r.size);
    if (r.engine == "Weft" &&
        std::find(options.weftThreads.begin(), options.weftThreads.end(), r.threads) == options.weftThreads.end()) {
      options.weftThreads.push_back(r.threads);
    }
  }
  if (options.weftThreads.empty()) options.weftThreads = {1};
  nlohmann::json verdicts = nlohmann::json::array();
  std::cout << "Command: `" << document.value("command", std::string()) << "`\n" << makeReport(runs, options, verdicts);
  return 0;
}

int run(const Options& options, const std::string& commandLine) {
  std::vector<bool> modes;
  if (options.selfCollision != "on") modes.push_back(false);
  if (options.selfCollision != "off") modes.push_back(true);
  std::cout << "weft-vs-bullet: the curtain in Weft and Bullet " << "(soft body, single precision), "
            << options.frames << " frames"
            << (options.largeFrames ? " (" + std::to_string(options.largeFrames) + " from size 16 on)" : std::string())
            << "\n  machine: " << std::thread::hardware_concurrency()
            << " hardware threads; timings are wall-clock and the machine may be shared\n"
            << std::flush;
  std::vector<RunRecord> runs;
  for (unsigned size : options.sizes) {
    const unsigned frames = size >= 16 && options.largeFrames > 0 ? options.largeFrames : options.frames;
    int lastSweepPoint = 1;  // Bullet iterations where the sweep without self-collision ended
    for (bool self : modes) {
      for (unsigned threads : options.weftThreads) {
        // Without self-collision Weft serves as the strain target and a like-for-like time point;
        // its thread scaling is measured where it matters, with self-collision on.
        if (!self && threads != options.weftThreads.front() && !options.allThreadsWithoutSelfCollision) continue;
        runs.push_back(runWeft(size, threads, self, frames));
        if (!options.quiet) std::cout << progressLine(runs.back()) << "\n" << std::flush;
      }
      const RunRecord* weft = findWeft(runs, size, self, options.weftThreads.front());
      const double target = weft ? weft->measured.maxStrain : 0;
      const double targetBeforeGather = weft ? weft->measured.maxStrainBeforeGather : 0;
      std::vector<int> schedule = options.iterations;
      const bool adaptive = schedule.empty();
      if (self && size > options.bulletSelfCollisionMaxSize) {
        std::cout << "  x" << size << " Bullet self on: not run (per-face clusters need a faces x faces "
                  << "connectivity table; raise --bullet-self-collision-max-size to try)\n" << std::flush;
        continue;
      }
      if (adaptive && self) {
        // Cluster self-collision costs far more than the links; run Bullet's default and the point
        // where the sweep without self-collision ended, which collisions do not make less strained.
        schedule = {1};
        if (lastSweepPoint > 1) schedule.push_back(lastSweepPoint);
      } else if (adaptive) {
        const int factor = size >= 16 ? options.largeIterationFactor : options.iterationFactor;
        for (int n = 1; n <= options.maxIterations; n *= factor) schedule.push_back(n);
      }
      double previous = -1, previousBeforeGather = -1;
      for (int iterations : schedule) {
        BulletCurtainSettings settings = options.bullet;
        settings.size = size;
        settings.selfCollision = self;
        settings.positionIterations = iterations;
        runs.push_back(runBullet(settings, frames));
        const RunRecord& r = runs.back();
        if (!options.quiet) std::cout << progressLine(r) << "\n" << std::flush;
        if (!self) lastSweepPoint = iterations;
        if (!adaptive || self || r.failed || blewUp(r.measured)) continue;
        // Stop once both strains reached Weft's or stopped improving (less than kStallFraction).
        const double strain = r.measured.maxStrain, early = r.measured.maxStrainBeforeGather;
        const bool wholeDone = strain <= target || (previous > 0 && strain > previous * (1 - kStallFraction));
        const bool earlyDone = early <= targetBeforeGather ||
                               (previousBeforeGather > 0 && early > previousBeforeGather * (1 - kStallFraction));
        if (wholeDone && earlyDone) break;
        previous = strain;
        previousBeforeGather = early;
      }
    }
  }

  nlohmann::json verdicts = nlohmann::json::array();
  std::ostringstream report;
  report << makeReport(runs, options, verdicts);
  std::cout << report.str() << std::flush;

  if (!options.markdown.empty()) {
    std::ofstream file(options.markdown);
    if (!file) {
      std::cerr << "weft-vs-bullet: cannot write '" << options.markdown << "'; check that its folder exists\n";
      return 1;
    }
    file << "Command: `" << commandLine << "`\n" << report.str();
  }
  if (!options.json.empty()) {
    nlohmann::json document = {{"command", commandLine},
                               {"frames", options.frames},
                               {"large_frames", options.largeFrames},
                               {"hardware_threads", std::thread::hardware_concurrency()},
                               {"bullet_settings",
                                {{"stretch_kLST", options.bullet.stretchStiffness},
                                 {"bending_stiffness_per_frame", options.bullet.bendingStiffnessPerFrame},
                                 {"collision_margin_m", options.bullet.collisionMargin},
                                 {"sdf_voxel_m", options.bullet.sdfVoxelSize},
                                 {"friction_kDF", options.bullet.friction},
                                 {"damping_rate_per_s", options.bullet.dampingRate},
                                 {"substeps", options.bullet.substeps}}},
                               {"runs", nlohmann::json::array()},
                               {"verdicts", verdicts}};
    for (const RunRecord& r : runs) document["runs"].push_back(toJson(r));
    std::ofstream file(options.json);
    if (!file) {
      std::cerr << "weft-vs-bullet: cannot write '" << options.json << "'; check that its folder exists\n";
      return 1;
    }
    file << document.dump(2) << "\n";
  }
  for (const RunRecord& r : runs) {
    if (r.failed) return 1;
  }
  return 0;
}

}  // namespace
}  // namespace weft

int main(int argc, char** argv) {
  weft::Options options;
  CLI::App app{"weft-vs-bullet: the curtain in Weft and in Bullet's soft body, side by side (bench/peers/README.md)"};
  app.add_option("--sizes", options.sizes, "Curtain sizes, comma-separated (1, 4, 16, 64)")
      ->delimiter(',')
      ->check(CLI::IsMember({1u, 4u, 16u, 64u}));
  app.add_option("--frames", options.frames, "Frames per run (600 = the 10 s script)")->check(CLI::Range(2u, 100000u));
  app.add_option("--large-frames", options.largeFrames,
                 "Frames per run from size 16 on (0: as --frames); Weft takes over a second a frame there")
      ->check(CLI::Range(0u, 100000u));
  app.add_option("--weft-threads", options.weftThreads, "Weft thread counts, comma-separated")
      ->delimiter(',')
      ->check(CLI::Range(1u, 256u));
  app.add_option("--self-collision", options.selfCollision, "off, on or both")->check(CLI::IsMember({"off", "on", "both"}));
  app.add_option("--iterations", options.iterations,
                 "Bullet position iterations to run, comma-separated (default: the adaptive sweep)")
      ->delimiter(',')
      ->check(CLI::Range(1, 10000));
  app.add_option("--iteration-factor", options.iterationFactor, "Sweep: iterations grow by this factor (sizes 1, 4)")
      ->check(CLI::Range(2, 16));
  app.add_option("--large-iteration-factor", options.largeIterationFactor,
                 "Sweep: iterations grow by this factor from size 16 on")
      ->check(CLI::Range(2, 16));
  app.add_option("--max-iterations", options.maxIterations, "Sweep: highest Bullet position iterations")
      ->check(CLI::Range(1, 10000));
  app.add_option("--bullet-self-collision-max-size", options.bulletSelfCollisionMaxSize,
                 "Largest size at which Bullet runs with self-collision");
  app.add_option("--bullet-substeps", options.bullet.substeps, "Bullet steps per 1/60 s frame")->check(CLI::Range(1, 64));
  app.add_option("--bullet-bending", options.bullet.bendingStiffnessPerFrame,
                 "Bullet bending links: violation removed per frame, in [0, 1)")
      ->check(CLI::Range(0.0, 0.999));
  app.add_option("--bullet-margin", options.bullet.collisionMargin,
                 "Bullet collision margin, m (0: a fifth of the grid spacing)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--json", options.json, "Write all runs and verdicts as JSON here");
  app.add_option("--markdown", options.markdown, "Write the table and verdicts as markdown here");
  app.add_flag("--all-threads-without-self-collision", options.allThreadsWithoutSelfCollision,
               "Run Weft on every --weft-threads count with self-collision off too (default: the first only)");
  app.add_flag("--quiet", options.quiet, "No line per run");
  std::string reportFromPath;
  app.add_option("--report-from", reportFromPath, "Print the table and verdicts of a --json file; run nothing");
  CLI11_PARSE(app, argc, argv);
  if (!reportFromPath.empty()) return weft::reportFrom(reportFromPath, options);
  if (options.weftThreads.empty()) options.weftThreads = {1};
  std::string commandLine;
  for (int k = 0; k < argc; ++k) commandLine += (k ? " " : "") + std::string(argv[k]);
  return weft::run(options, commandLine);
}
