// The curtain runner: the frame loop of the main job (docs/curtain-benchmark.md).
//
// It steps the curtain scene frame by frame, as a game would, timing each frame's simulation
// (and rendering, when weft::render is built and --render is not off), and writes a report, a
// JSON summary, and optionally a per-frame CSV with a chart of it beside (gnuplot).
#pragma once

#include <weft/engine/SolverSettings.h>

#include <cstdint>
#include <iosfwd>
#include <string>

namespace weft {

/// Command-line options of weft-curtain.
struct CurtainRunOptions {
  unsigned size = 1;               ///< 1, 4, 16 or 64
  unsigned frames = 600;           ///< frames to run (600 = the full 10 s script)
  unsigned threads = 0;            ///< worker threads (0 = all cores)
  unsigned renderWidth = 1280;     ///< pixels; 0 = render off
  unsigned renderHeight = 720;     ///< pixels
  bool selfCollision = true;       ///< self-collision on (needs the collision module)
  bool checkIntersections = false; ///< count intersecting triangle pairs every frame (untimed)
  /// Simulation budget per frame in ms, handed to the engine (World::step(frameDt, budget)),
  /// which plans each frame to fit and reports misses; 0 = none.
  double budgetMs = 0;
  bool skips = true;               ///< skip stages the scene does not need (off: run every stage)
  bool sleep = true;               ///< let the curtain sleep when at rest
  std::string captureDirectory;    ///< where PNG frames go; empty = no capture
  std::string summaryJson;         ///< JSON summary path; empty = none
  std::string frameCsv;            ///< per-frame CSV path, with a PNG chart beside it; empty = none
  std::string trace;               ///< Chrome trace-event JSON path (Perfetto); empty = no profiling
  IntegratorKind integrator = IntegratorKind::ImplicitEuler;  ///< time integrator
  std::string fabric = "cotton";   ///< the curtain's fabric preset (fabricPresetNames())
  bool stiffening = false;         ///< the preset with its KES tensile test (stiffeningFabricPreset)
  double strainLimit = -1;         ///< overrides the preset's strain limit when ≥ 0 (0 = off)
  bool progress = true;            ///< print a progress line every second of simulated time
  bool overlap = true;             ///< render frame k while simulating frame k+1 (off: in turn)
};

/// Runs the curtain and prints the report to `out`. Returns a process exit code: 0 when the run
/// completed with finite state, 1 otherwise (the report says why), 2 on bad options.
int runCurtain(const CurtainRunOptions& options, std::ostream& out);

}  // namespace weft
