// The error-vs-time sweep (weft-error-time): how much accuracy each integrator, step size and
// PCG tolerance buys per second of CPU time, on the curtain (against a reference shown to
// converge, phase by phase, with Bullet's soft body on the same front), and the order and
// numerical damping of the implicit integrators on a free drape and a pendulum.
#pragma once

#include <weft/Math.h>

#include <ostream>
#include <string>

namespace weft {

/// Options of one sweep (flags in ErrorTimeMain.cpp).
struct ErrorTimeOptions {
  std::string scene = "curtain";  ///< curtain (the sweep), drape (orders) or pendulum (damping)
  bool quick = false;             ///< the curtain's first 3 s and a small grid (minutes)
  bool full = false;              ///< every combination and the whole 10 s script (hours)
  std::string csvPath;            ///< one row per run and phase; empty = no CSV
  std::string plotPath;           ///< PNG of error against time per phase (gnuplot); empty = none
  std::string markdownPath;       ///< the tables as markdown; empty = none
  std::string referenceCache;     ///< file the references are read from / written to; empty = none
  std::string referenceIntegrator = "bdf2";  ///< integrator of the reference (integratorName)
  Index referenceSubsteps = 32;   ///< substeps per 1/60 s frame of the reference
  int referenceNewtonIterations = 2;  ///< Newton iterations per reference step
  Real referenceCgTolerance = 1e-10;  ///< PCG relative residual of the reference
  int repeats = 1;                ///< runs per configuration, in rounds over the grid; the least
                                  ///< CPU time is kept
  bool progress = true;           ///< one line per run while sweeping
  bool bullet = true;             ///< Bullet's soft body on the front (when built with Bullet)
  /// Exit with status 3 when SolverSettings{} is dominated by more than the timing noise by a run
  /// whose error the reference tells apart from theirs (the defaults-on-the-front check).
  bool checkDefaults = false;
  /// Runs only the configurations whose description contains this text (e.g. "h=1/60 "), and
  /// always SolverSettings{}; empty = every configuration of the grid.
  std::string only;
};

/// Runs the sweep (or the drape / pendulum study) and prints its tables; 0 on success, 1 when the
/// reference is unhealthy, 2 on bad options, 3 when checkDefaults finds the defaults dominated.
int runErrorTime(const ErrorTimeOptions& options, std::ostream& out);

/// The drape and pendulum studies (IntegratorStudy.cpp): orders on a smooth free drape and the
/// damping of a pendulum at the default step, for backward Euler and BDF2.
int runIntegratorStudy(const ErrorTimeOptions& options, std::ostream& out);

}  // namespace weft
