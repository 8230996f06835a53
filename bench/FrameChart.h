// FrameChart: a PNG chart of per-frame times drawn by gnuplot from the curtain runner's CSV.
//
// The runner writes a gnuplot script beside the chart (so a user can restyle and rerun it) and
// runs gnuplot on it; the data stay in the CSV, which the script reads by column name. gnuplot is
// an optional tool: when it is not installed the chart is skipped with a message, never an error.
// Rejected: drawing the chart with the project's own PNG writer (a plotting library of our own to
// maintain for one picture).
#pragma once

#include <string>
#include <vector>

namespace weft {

/// A shaded interval of the x axis with a label (a phase of the scene's script).
struct ChartPhase {
  double beginFrame = 0;  ///< frame number where the phase starts
  double endFrame = 0;    ///< frame number where it ends
  std::string name;       ///< label drawn at the top of the band
};

/// What the chart shows.
struct FrameChartSettings {
  std::string csvPath;     ///< the runner's per-frame CSV (columns frame, sim_ms, render_ms, frame_ms)
  std::string pngPath;     ///< where the chart goes
  std::string scriptPath;  ///< where its gnuplot script goes
  std::string title;       ///< chart title
  unsigned frames = 0;     ///< frames in the CSV
  bool rendering = false;  ///< plot render_ms and frame_ms too
  double budgetMs = 0;     ///< ms, a horizontal budget line; 0 = none
  double targetMs = 0;     ///< ms, a horizontal simulation-target line; 0 = none
  std::vector<ChartPhase> phases;  ///< shaded bands, in order
};

/// What became of the chart.
struct FrameChartOutcome {
  bool written = false;  ///< the PNG is on disk
  bool skipped = false;  ///< gnuplot is not installed: nothing written, not an error
  std::string message;   ///< why it was skipped or failed; empty when written
};

/// Writes the gnuplot script and runs gnuplot on it (waits for it to finish).
FrameChartOutcome writeFrameChart(const FrameChartSettings& settings);

}  // namespace weft
