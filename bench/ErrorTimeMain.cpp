// weft-error-time: command line of the error-vs-time sweep and the integrator studies.
// CLI11 is included here and nowhere else: it costs ~12 s of compile time per file.
#include "ErrorTime.h"

#include <CLI/CLI.hpp>

#include <iostream>

int main(int argc, char** argv) {
  weft::ErrorTimeOptions options;
  CLI::App app{"Weft error-vs-time sweep: integrators x steps x PCG tolerances on the curtain "
               "against a reference shown to converge, per phase of the script, with Bullet on the "
               "same front; --scene drape and pendulum measure the implicit integrators' order and "
               "damping"};
  app.add_option("--scene", options.scene, "curtain (the sweep), drape (orders) or pendulum (damping)")
      ->check(CLI::IsMember({"curtain", "drape", "pendulum"}));
  app.add_flag("--quick", options.quick, "The curtain's first 3 s and a small grid (tens of minutes)");
  app.add_flag("--full", options.full, "Every combination over the whole 10 s script (hours)");
  app.add_option("--csv", options.csvPath, "Write one row per run and phase here");
  app.add_option("--plot", options.plotPath,
                 "Write a PNG of error against CPU time per phase here (gnuplot)");
  app.add_option("--markdown", options.markdownPath, "Write the tables as markdown here");
  app.add_option("--reference-cache", options.referenceCache,
                 "Read the references from FILE.ref and FILE.check, or compute and write them");
  app.add_option("--reference-integrator", options.referenceIntegrator,
                 "Integrator of the reference: bdf2 or implicit-euler")
      ->check(CLI::IsMember({"bdf2", "implicit-euler"}));
  app.add_option("--reference-substeps", options.referenceSubsteps,
                 "Substeps per 1/60 s frame of the reference (its check takes twice as many)")
      ->check(CLI::Range(8u, 4096u));
  app.add_option("--reference-newton", options.referenceNewtonIterations,
                 "Newton iterations per reference step")
      ->check(CLI::Range(0, 10));
  app.add_option("--repeat", options.repeats,
                 "Runs per configuration, in rounds over the whole grid; the least CPU time is "
                 "kept (errors are identical)")
      ->check(CLI::Range(1, 20));
  app.add_option("--only", options.only,
                 "Run only the configurations whose description contains this text (the defaults "
                 "always run), e.g. \"bdf2-verr h=1/60 \"");
  bool noBullet = false;
  app.add_flag("--no-bullet", noBullet, "Leave Bullet's points out");
  app.add_flag("--check-defaults", options.checkDefaults,
               "Exit with status 3 when SolverSettings{} is dominated beyond the timing noise by a "
               "run whose error the reference tells apart (by vertex distance or statistics)");
  bool quiet = false;
  app.add_flag("--quiet", quiet, "No line per run");
  CLI11_PARSE(app, argc, argv);
  if (options.quick && options.full) {
    std::cerr << "weft-error-time: --quick and --full exclude each other; choose one\n";
    return 2;
  }
  options.progress = !quiet;
  options.bullet = !noBullet;
  return weft::runErrorTime(options, std::cout);
}
