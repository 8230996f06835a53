// weft-error-time: command line of the error-vs-time sweep.
// CLI11 is included here and nowhere else: it costs ~12 s of compile time per file.
#include "ErrorTime.h"

#include <CLI/CLI.hpp>

#include <iostream>

int main(int argc, char** argv) {
  weft::ErrorTimeOptions options;
  CLI::App app{"Weft error-vs-time sweep: integrator x step size x PCG tolerance x warm start on "
               "the curtain, against a cached backward-Euler reference; prints the Pareto front"};
  app.add_option("--scene", options.scene, "Scene to sweep (curtain)")
      ->check(CLI::IsMember({"curtain"}));
  app.add_flag("--quick", options.quick, "About 2 s simulated and a small grid (a few minutes)");
  app.add_flag("--full", options.full, "Every combination, 6 s simulated (slow)");
  app.add_option("--csv", options.csvPath, "Write one row per run here");
  app.add_option("--plot", options.plotPath, "Write a PNG of error against time here (gnuplot)");
  app.add_option("--markdown", options.markdownPath,
                 "Write the Pareto front and where SolverSettings{} sits as a markdown table");
  app.add_option("--reference-cache", options.referenceCache,
                 "Read the reference from this file, or compute and write it there");
  app.add_option("--reference-substeps", options.referenceSubsteps,
                 "Backward-Euler substeps per 1/60 s frame of the reference (at least 16)")
      ->check(CLI::Range(16u, 4096u));
  app.add_option("--repeat", options.repeats,
                 "Runs per configuration; the fastest wall time is kept (errors are identical)")
      ->check(CLI::Range(1, 20));
  app.add_option("--only", options.only,
                 "Run only the configurations whose description contains this text (the defaults "
                 "always run), e.g. \"implicit-euler h=1/60 \"");
  bool quiet = false;
  app.add_flag("--quiet", quiet, "No line per run");
  CLI11_PARSE(app, argc, argv);
  if (options.quick && options.full) {
    std::cerr << "weft-error-time: --quick and --full exclude each other; choose one\n";
    return 2;
  }
  options.progress = !quiet;
  return weft::runErrorTime(options, std::cout);
}
