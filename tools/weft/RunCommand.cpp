// weft run: simulate a scene file frame by frame, optionally draw, capture and export, and
// report frame times, solver figures, contacts, status flags and the state hash.
//
// Exit status: 0 when the run completed, 1 on an error, 2 on bad options, and 3 when
// --check-intersections found an intersecting triangle pair in any frame (the report is complete
// and the summary written either way), so that scripts and CI can gate on it.
//
// Timing covers stepFrame() only (scripts + World::step); drawing, intersection counting and OBJ
// export are measured apart or not at all, so the simulation figures mean the same with and
// without them. Frame 1 is left out of the percentiles: it pays for first-touch page faults.
#include "Commands.h"
#include <weft/threading/SampleStatistics.h>

#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/engine/ObjWriter.h>
#include <weft/scenes/ScriptedScene.h>

#if WEFT_HAVE_RENDER
#include "SceneDrawing.h"
#endif

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

namespace weft {
namespace {

using Clock = std::chrono::steady_clock;

std::string hex(std::uint64_t value) {
  std::ostringstream text;
  text << "0x" << std::hex << std::setw(16) << std::setfill('0') << value;
  return text.str();
}

// A file name from a cloth's name: letters, digits, '-' and '_' kept, the rest turned into '_'.
std::string fileStem(const std::string& name) {
  std::string stem;
  for (char c : name) stem += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return stem.empty() ? std::string("cloth") : stem;
}

// Parses "WxH"; false when it is not a resolution.
bool parseResolution(const std::string& text, int& width, int& height) {
  std::istringstream stream(text);
  char separator = 0;
  return bool(stream >> width >> separator >> height) && stream.peek() == EOF && separator == 'x' &&
         width >= 16 && height >= 16 && width <= 16384 && height <= 16384;
}

// Counts of each status flag over the run.
struct StatusCounts {
  unsigned unstable = 0, notConverged = 0, rolledBack = 0, retried = 0, invalid = 0, overLimit = 0,
           squeezed = 0, frozen = 0, unresolved = 0;
  void add(StepStatus s) {
    unstable += hasFlag(s, StepStatus::Unstable);
    notConverged += hasFlag(s, StepStatus::SolverNotConverged);
    rolledBack += hasFlag(s, StepStatus::RolledBack);
    retried += hasFlag(s, StepStatus::RetriedWithSmallerStep);
    invalid += hasFlag(s, StepStatus::InvalidInput);
    overLimit += hasFlag(s, StepStatus::StrainLimitExceeded);
    squeezed += hasFlag(s, StepStatus::Squeezed);
    frozen += hasFlag(s, StepStatus::ContactsFrozen);
    unresolved += hasFlag(s, StepStatus::ContactsUnresolved);
  }
  std::string describe() const {
    std::string text;
    auto item = [&](unsigned count, const char* name) {
      if (count) text += (text.empty() ? "" : ", ") + std::string(name) + " in " + std::to_string(count) + " frame(s)";
    };
    item(unstable, "unstable");
    item(notConverged, "solver-not-converged");
    item(retried, "retried-with-smaller-step");
    item(rolledBack, "rolled-back");
    item(invalid, "invalid-input");
    item(overLimit, "strain-limit-exceeded");
    item(squeezed, "squeezed");
    item(frozen, "contacts-frozen");
    item(unresolved, "contacts-unresolved");
    return text.empty() ? "ok in every frame" : text;
  }
};

// Progress: a bar redrawn in place on a terminal, a plain line every tenth of the run otherwise.
class Progress {
 public:
  Progress(std::ostream& out, long frames, bool quiet)
      : m_out(out), m_frames(frames), m_quiet(quiet), m_terminal(isatty(STDOUT_FILENO) == 1) {}

  void update(long frame, double simulationMs, StepStatus status) {
    if (m_quiet) return;
    if (m_terminal) {
      if (frame % 2 != 0 && frame != m_frames) return;  // every other frame is plenty
      constexpr int kWidth = 30;
      const int filled = int(kWidth * frame / m_frames);
      m_out << "\r  [" << std::string(filled, '#') << std::string(kWidth - filled, '.') << "] "
            << frame << "/" << m_frames << "  sim " << std::fixed << std::setprecision(2)
            << simulationMs << " ms  " << weft::describe(status) << "   " << std::flush;
      if (frame == m_frames) m_out << "\n";
      return;
    }
    const long every = std::max(1L, m_frames / 10);
    if (frame % every == 0 || frame == m_frames) {
      m_out << "  frame " << frame << "/" << m_frames << "  sim " << std::fixed
            << std::setprecision(2) << simulationMs << " ms  status " << weft::describe(status)
            << "\n" << std::flush;
    }
  }

 private:
  std::ostream& m_out;
  long m_frames;
  bool m_quiet, m_terminal;
};

}  // namespace

int runScene(const RunOptions& options, std::ostream& out) {
  Result<SceneDescription> description = loadSceneFile(options.scene);
  if (!description.ok()) {
    out << "weft run: " << description.error().message << "\n";
    return 1;
  }
  const long frames = options.frames > 0 ? options.frames : long(description->frames);
  ScriptedSceneSettings sceneSettings;
  sceneSettings.threadCount = options.threads;
  Result<ScriptedScene> created = ScriptedScene::create(std::move(description).value(), sceneSettings);
  if (!created.ok()) {
    out << "weft run: scene file '" << options.scene << "': " << created.error().message << "\n";
    return 1;
  }
  ScriptedScene& scene = created.value();
  const SceneDescription& scenario = scene.description();

  // What to draw at which size: --render WxH, "camera", or implied by --capture.
  int width = 0, height = 0;
  if (options.render == "camera" || (options.render == "off" && !options.captureDirectory.empty())) {
    width = scenario.camera.width;
    height = scenario.camera.height;
  } else if (options.render != "off" && !parseResolution(options.render, width, height)) {
    out << "weft run: --render '" << options.render
        << "' is not a resolution; give WIDTHxHEIGHT (16 to 16384, e.g. 1280x720), camera or off\n";
    return 2;
  }
  const bool rendering = width > 0;

  Index triangles = 0, vertices = 0;
  for (const ClothDescription& cloth : scenario.cloths) {
    triangles += cloth.model->triangleCount();
    vertices += cloth.model->vertexCount();
  }
  out << "weft run " << scenario.name << " (" << options.scene << ")\n"
      << "  cloths     " << scenario.cloths.size() << " (" << vertices << " vertices, " << triangles
      << " triangles), colliders " << scenario.colliders.size() << "\n"
      << "  frames     " << frames << " of " << scenario.frameDt * 1000 << " ms ("
      << frames * scenario.frameDt << " s simulated), threads " << scene.world().threadCount() << "\n";
  if (!options.quiet && !scenario.description.empty()) out << "  about      " << scenario.description << "\n";
  for (const ClothDescription& cloth : scenario.cloths) {
    const MeshImport& import = cloth.model->meshImport();
    if (import.weldedVertices == 0 && import.flippedTriangles == 0) continue;
    out << "  mesh       '" << cloth.name << "': welded " << import.weldedVertices
        << " coincident vertices, flipped " << import.flippedTriangles << " triangles\n";
  }

#if WEFT_HAVE_RENDER
  std::unique_ptr<SceneDrawing> drawing;
  if (rendering) {
    Result<std::unique_ptr<SceneDrawing>> started =
        SceneDrawing::create(scene, width, height, options.captureDirectory);
    if (!started.ok()) {
      out << "weft run: cannot render: " << started.error().message
          << "\n  (run with --render off to simulate only)\n";
      return 1;
    }
    drawing = std::move(started).value();
    out << "  render     " << width << " x " << height << " on " << drawing->rendererName();
    if (drawing->undrawnColliders()) out << " (" << drawing->undrawnColliders() << " mesh collider(s) not drawn)";
    out << "\n";
    if (!options.captureDirectory.empty()) {
      out << "  capture    every " << options.captureEvery << " frame(s) to " << options.captureDirectory << "\n";
    }
  }
#else
  if (rendering) {
    out << "weft run: this weft was built without rendering (WEFT_BUILD_RENDER=OFF); "
           "run with --render off and without --capture\n";
    return 2;
  }
#endif

  if (!options.exportObjDirectory.empty()) {
    std::error_code error;
    std::filesystem::create_directories(options.exportObjDirectory, error);
    if (error) {
      out << "weft run: cannot create the folder '" << options.exportObjDirectory
          << "': " << error.message() << "; choose a writable location\n";
      return 1;
    }
  }
  // One counter over every cloth at once (vertex indices offset per cloth), so that pairs between
  // two cloths count as well as pairs within one.
  std::optional<SelfIntersectionCounter> counter;
  std::vector<Vec3> allPositions;
  if (options.checkIntersections) {
    std::vector<Index> allIndices;
    for (const ClothDescription& cloth : scenario.cloths) {
      const Index base = Index(allPositions.size());
      for (Index index : cloth.model->indices()) allIndices.push_back(base + index);
      allPositions.insert(allPositions.end(), cloth.model->restPositions().begin(), cloth.model->restPositions().end());
    }
    Result<SelfIntersectionCounter> created = SelfIntersectionCounter::create(allIndices, allPositions);
    if (!created.ok()) {
      out << "weft run: " << created.error().message << "\n";
      return 1;
    }
    counter.emplace(std::move(created).value());
    out << "  checking   intersecting triangle pairs, within and between cloths, every frame (not timed)\n";
  }
  out << std::flush;

  std::vector<double> simulationMs, renderMs;
  simulationMs.reserve(std::size_t(frames));
  StatusCounts statuses;
  StepStatus seen = StepStatus::Ok;
  double maxStrain = 0;
  Index maxContacts = 0, maxSelfContacts = 0, maxIntersections = 0, framesWithIntersections = 0;
  long firstIntersectingFrame = 0;  // 0: none
  long cgIterations = 0;
  unsigned exported = 0;
  Progress progress(out, frames, options.quiet);
  const auto runStart = Clock::now();
  for (long frame = 1; frame <= frames; ++frame) {
    const auto start = Clock::now();
    const StepStatus status = scene.stepFrame();
    simulationMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
    const StepStats& stats = scene.world().stats();
    statuses.add(status);
    seen |= status;
    maxStrain = std::max(maxStrain, stats.maxStrain);
    maxContacts = std::max(maxContacts, stats.contacts);
    maxSelfContacts = std::max(maxSelfContacts, stats.selfContacts);
    cgIterations += stats.cgIterations;
#if WEFT_HAVE_RENDER
    if (drawing) {
      const bool capture = !options.captureDirectory.empty() && frame % options.captureEvery == 0;
      Result<double> drawn = drawing->draw(scene, capture);
      if (!drawn.ok()) {
        out << "\nweft run: rendering frame " << frame << " failed: " << drawn.error().message << "\n";
        return 1;
      }
      renderMs.push_back(drawn.value());
    }
#endif
    if (counter) {
      allPositions.clear();
      for (std::size_t k = 0; k < scene.clothCount(); ++k) {
        const std::span<const Vec3> x = scene.world().positions(scene.cloth(k)).value();
        allPositions.insert(allPositions.end(), x.begin(), x.end());
      }
      const Index pairs = counter->count(allPositions);
      maxIntersections = std::max(maxIntersections, pairs);
      framesWithIntersections += pairs > 0;
      if (pairs > 0 && firstIntersectingFrame == 0) firstIntersectingFrame = frame;
    }
    if (!options.exportObjDirectory.empty() && (frame % options.exportEvery == 0 || frame == frames)) {
      for (std::size_t k = 0; k < scene.clothCount(); ++k) {
        char number[32];
        std::snprintf(number, sizeof number, "_%05ld.obj", frame);
        const std::string path = (std::filesystem::path(options.exportObjDirectory) /
                                  (fileStem(scenario.cloths[k].name) + number)).string();
        const std::string comment = "weft: scene " + scenario.name + ", cloth " +
                                    scenario.cloths[k].name + ", frame " + std::to_string(frame) +
                                    ", t = " + std::to_string(scene.world().time()) + " s";
        Status written = writeObj(path, scene.world().renderView(scene.cloth(k)).value(), comment);
        if (!written.ok()) {
          out << "\nweft run: " << written.error().message << "\n";
          return 1;
        }
        ++exported;
      }
    }
    progress.update(frame, simulationMs.back(), status);
  }
#if WEFT_HAVE_RENDER
  if (drawing) {
    Status finished = drawing->finish();
    if (!finished.ok()) {
      out << "weft run: capture failed: " << finished.error().message << "\n";
      return 1;
    }
  }
#endif
  const double wallSeconds = std::chrono::duration<double>(Clock::now() - runStart).count();

  // Percentiles leave frame 1 out (cold caches, first-touch page faults) when there are others.
  const std::vector<double> steady(simulationMs.begin() + (simulationMs.size() > 1 ? 1 : 0), simulationMs.end());
  const std::vector<double> steadyRender(renderMs.begin() + (renderMs.size() > 1 ? 1 : 0), renderMs.end());
  const std::uint64_t hash = scene.world().stateHash();
  out << std::fixed << std::setprecision(3) << "\nReport\n"
      << "  frames         " << frames << " (" << std::setprecision(2) << wallSeconds << " s wall)\n"
      << std::setprecision(3) << "  simulation ms  p50 " << percentile(steady, 50)
      << "  p95 " << percentile(steady, 95) << "  p99 " << percentile(steady, 99)
      << "  max " << percentile(steady, 100) << "\n";
  if (rendering) {
    out << "  render ms      p50 " << percentile(steadyRender, 50) << "  p95 "
        << percentile(steadyRender, 95) << "  p99 " << percentile(steadyRender, 99)
        << "  (draw + read back " << width << " x " << height << ")\n";
  }
  out << std::setprecision(1) << "  CG iterations  " << double(cgIterations) / double(frames) << " per frame\n"
      << std::setprecision(5) << "  max strain     " << maxStrain << "\n"
      << "  contacts       " << maxContacts << " vertices on colliders at most; " << maxSelfContacts
      << " self-contact pairs at most\n"
      << "  status         " << statuses.describe() << "\n";
  if (counter) {
    out << "  intersections  " << maxIntersections << " pairs at most, in " << framesWithIntersections
        << " frame(s)";
    if (firstIntersectingFrame > 0) out << ", the first after frame " << firstIntersectingFrame;
    out << "\n";
  }
  if (!options.exportObjDirectory.empty()) {
    out << "  exported       " << exported << " OBJ file(s) to " << options.exportObjDirectory << "\n";
  }
  out << "  state hash     " << hex(hash) << "\n";

  if (!options.summaryJson.empty()) {
    nlohmann::json summary = {
        {"scene", scenario.name},
        {"frames", frames},
        {"triangles", triangles},
        {"threads", scene.world().threadCount()},
        {"sim_ms_p50", percentile(steady, 50)},
        {"sim_ms_p95", percentile(steady, 95)},
        {"sim_ms_p99", percentile(steady, 99)},
        {"render_ms_p50", rendering ? nlohmann::json(percentile(steadyRender, 50)) : nlohmann::json(nullptr)},
        {"max_strain", maxStrain},
        {"max_contacts", maxContacts},
        {"max_self_contacts", maxSelfContacts},
        {"status", describe(seen)},
        {"intersections", counter ? std::int64_t(maxIntersections) : std::int64_t(-1)},
        {"frames_with_intersections", counter ? std::int64_t(framesWithIntersections) : std::int64_t(-1)},
        {"first_intersecting_frame", counter ? std::int64_t(firstIntersectingFrame) : std::int64_t(-1)},
        {"state_hash", hex(hash)},
    };
    std::ofstream file(options.summaryJson);
    if (file) file << summary.dump(2) << "\n";
    if (!file) {
      out << "weft run: cannot write the summary to '" << options.summaryJson
          << "'; check that the folder exists and is writable\n";
      return 1;
    }
    out << "  summary        " << options.summaryJson << "\n";
  }
  if (framesWithIntersections > 0) {
    out << "weft run: FAILED --check-intersections: " << maxIntersections
        << " intersecting triangle pairs at most, in " << framesWithIntersections
        << " frame(s), the first after frame " << firstIntersectingFrame << "\n";
    return 3;
  }
  return 0;
}

}  // namespace weft
