// weft: the command line. Subcommands run, bench and validate (see Commands.h).
// CLI11 is included here and nowhere else: it costs ~12 s of compile time per file.
#include "Commands.h"

#include <CLI/CLI.hpp>

#include <iostream>

int main(int argc, char** argv) {
  CLI::App app{"Weft cloth simulation: run, time and check scene files (format: scenes/data/README.md)"};
  app.require_subcommand(1);

  weft::RunOptions run;
  CLI::App* runCommand = app.add_subcommand("run", "Simulate a scene file and report");
  runCommand->add_option("scene", run.scene, "Scene file (.json)")->required();
  runCommand->add_option("--frames", run.frames, "Frames to run (default: the scene's run length)")
      ->check(CLI::Range(1L, 100000000L));
  runCommand->add_option("--threads", run.threads, "Threads (0 = all cores)")->check(CLI::Range(0, 1024));
  runCommand->add_option("--render", run.render,
                         "Draw every frame: WxH, camera (the scene's resolution) or off")
      ->default_str("off");
  runCommand->add_option("--capture", run.captureDirectory,
                         "Write PNG frames here (renders at the camera resolution unless --render WxH)");
  runCommand->add_option("--capture-every", run.captureEvery, "Capture every Nth frame")->check(CLI::PositiveNumber);
  runCommand->add_option("--export-obj", run.exportObjDirectory, "Write every cloth as OBJ files here");
  runCommand->add_option("--export-every", run.exportEvery, "Export every Nth frame (and the last)")
      ->check(CLI::PositiveNumber);
  runCommand->add_flag("--check-intersections", run.checkIntersections,
                       "Count intersecting triangle pairs every frame (not timed); exit status 3 if any frame has one");
  runCommand->add_flag("--quiet", run.quiet, "No progress output");
  runCommand->add_option("--summary-json", run.summaryJson, "Write the report as JSON here");

  weft::BenchOptions bench;
  CLI::App* benchCommand = app.add_subcommand("bench", "Time a scene's simulation over repeated runs (no rendering)");
  benchCommand->add_option("scene", bench.scene, "Scene file (.json)")->required();
  benchCommand->add_option("--frames", bench.frames, "Frames per run (default: the scene's, at most 120)")
      ->check(CLI::Range(1L, 100000000L));
  benchCommand->add_option("--repeats", bench.repeats, "Runs, each from a fresh world")->check(CLI::Range(1, 1000));
  benchCommand->add_option("--threads", bench.threads, "Threads (0 = all cores)")->check(CLI::Range(0, 1024));

  weft::ValidateOptions validate;
  CLI::App* validateCommand = app.add_subcommand("validate", "Check scene files; errors name their JSON path");
  validateCommand->add_option("scenes", validate.scenes, "Scene files (.json)")->required();

  CLI11_PARSE(app, argc, argv);
  if (runCommand->parsed()) return weft::runScene(run, std::cout);
  if (benchCommand->parsed()) return weft::benchScene(bench, std::cout);
  return weft::validateScenes(validate, std::cout);
}
