// weft-curtain: command line of the curtain runner (flags and report: docs/curtain-benchmark.md).
// CLI11 is included here and nowhere else: it costs ~12 s of compile time per file.
#include "CurtainRunner.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <map>
#include <sstream>

int main(int argc, char** argv) {
  weft::CurtainRunOptions options;
  CLI::App app{"Weft curtain benchmark: simulate (and render) the curtain scene and report frame "
               "times (docs/curtain-benchmark.md)"};
  app.add_option("--size", options.size, "Refinement: 1, 4, 16 or 64 times 2,400 triangles")
      ->check(CLI::IsMember({1u, 4u, 16u, 64u}));
  app.add_option("--frames", options.frames, "Frames to run (600 = the 10 s script)")
      ->check(CLI::Range(1u, 1000000u));
  app.add_option("--threads", options.threads, "Worker threads (0 = all cores)");
  std::string render = "1280x720";
  app.add_option("--render", render, "Resolution WxH, or off");
  std::string selfCollision = "on";
  app.add_option("--self-collision", selfCollision, "on or off")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--capture", options.captureDirectory, "Directory for PNG frames");
  app.add_flag("--check-intersections", options.checkIntersections,
               "Count intersecting triangle pairs every frame (not timed)");
  app.add_option("--budget-ms", options.budgetMs,
                 "Simulation budget per frame in ms: the engine plans each frame to fit it and "
                 "reports misses (0 = none)")
      ->check(CLI::NonNegativeNumber);
  std::string skips = "on", sleep = "on";
  app.add_option("--skips", skips, "Skip stages the scene does not need: on or off")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--sleep", sleep, "Let the curtain sleep at rest: on or off")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_option("--summary-json", options.summaryJson, "Write the JSON summary here");
  app.add_option("--csv", options.frameCsv,
                 "Write per-frame statistics here (CSV), and a chart of them beside it (.png, gnuplot)");
  app.add_option("--trace", options.trace,
                 "Record profiler zones and write a Chrome trace here (open in Perfetto)");
  // Names come from the engine (integratorName), so the flag and the reports cannot disagree.
  std::map<std::string, weft::IntegratorKind> integrators;
  for (weft::IntegratorKind kind :
       {weft::IntegratorKind::ImplicitEuler, weft::IntegratorKind::ExplicitEuler,
        weft::IntegratorKind::SymplecticEuler, weft::IntegratorKind::Midpoint,
        weft::IntegratorKind::RungeKutta4, weft::IntegratorKind::Bdf2}) {
    integrators.emplace(weft::integratorName(kind), kind);
  }
  app.add_option("--integrator", options.integrator, "Time integrator")
      ->transform(CLI::CheckedTransformer(integrators, CLI::ignore_case));
  app.add_option("--fabric", options.fabric,
                 "Fabric preset of the curtain: cotton, wool, polyester, silk, denim or linen")
      ->check(CLI::IsMember({"cotton", "wool", "polyester", "silk", "denim", "linen"}));
  app.add_flag("--stiffening", options.stiffening,
               "The preset with its KES tensile test: stretch stiffening past a knee, limit at EMT");
  app.add_option("--strain-limit", options.strainLimit,
                 "Strain limit instead of the preset's (0 = off)")
      ->check(CLI::Range(0.0, 10.0));
  std::string overlap = "on";
  app.add_option("--overlap", overlap, "Render frame k while simulating frame k+1: on or off")
      ->check(CLI::IsMember({"on", "off"}));
  bool quiet = false;
  app.add_flag("--quiet", quiet, "No progress lines");
  CLI11_PARSE(app, argc, argv);

  options.selfCollision = selfCollision == "on";
  options.skips = skips == "on";
  options.sleep = sleep == "on";
  options.progress = !quiet;
  options.overlap = overlap == "on";
  if (render == "off") {
    options.renderWidth = options.renderHeight = 0;
  } else {
    unsigned width = 0, height = 0;
    char separator = 0;
    std::istringstream text(render);
    if (!(text >> width >> separator >> height) || separator != 'x' || width == 0 || height == 0 ||
        width > 16384 || height > 16384) {
      std::cerr << "weft-curtain: --render '" << render
                << "' is not a resolution; give WIDTHxHEIGHT (e.g. 1280x720) or off\n";
      return 2;
    }
    options.renderWidth = width;
    options.renderHeight = height;
  }
  return weft::runCurtain(options, std::cout);
}
