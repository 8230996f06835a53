// The error-vs-time sweep (weft-error-time): how much accuracy each integrator,
// step size, PCG tolerance and warm-start choice buys per second of wall time on the curtain.
#pragma once

#include <weft/Math.h>

#include <ostream>
#include <string>

namespace weft {

/// Options of one sweep (flags in ErrorTimeMain.cpp).
struct ErrorTimeOptions {
  std::string scene = "curtain";  ///< the only scene offered: the curtain
  bool quick = false;             ///< ~2 s simulated, a small grid of settings (minutes)
  bool full = false;              ///< every combination, 6 s simulated with the rod gathering
  std::string csvPath;            ///< one row per run; empty = no CSV
  std::string plotPath;           ///< PNG of error against time (gnuplot); empty = no plot
  std::string markdownPath;       ///< Pareto table and the defaults' place, markdown; empty = none
  std::string referenceCache;     ///< file the reference is read from / written to; empty = none
  Index referenceSubsteps = 16;   ///< substeps per 1/60 s frame of the backward-Euler reference
  int referenceNewtonIterations = 3;  ///< Newton iterations per reference step
  Real referenceCgTolerance = 1e-10;  ///< PCG relative residual of the reference
  int repeats = 1;                ///< runs per configuration; the fastest wall time is kept
  bool progress = true;           ///< one line per run while sweeping
  /// Runs only the configurations whose description contains this text (e.g. "h=1/60 "), and
  /// always SolverSettings{}; empty = every configuration of the grid.
  std::string only;
};

/// Runs the sweep, prints the Pareto front and where SolverSettings{} sits; 0 on success.
int runErrorTime(const ErrorTimeOptions& options, std::ostream& out);

}  // namespace weft
