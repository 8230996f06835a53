// The subcommands of the weft command line. main.cpp parses the arguments (CLI11) into these
// option structs; each command prints to `out` and returns the process exit code.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace weft {

/// `weft run SCENE`: simulate, optionally render, capture and export; report at the end.
struct RunOptions {
  std::string scene;             ///< scene file
  long frames = -1;              ///< −1: the scene's own run length
  int threads = 0;               ///< 0 = all cores
  std::string render = "off";    ///< "off", "camera" (the scene's resolution) or WxH
  std::string captureDirectory;  ///< PNG frames (needs rendering; implies the camera resolution)
  unsigned captureEvery = 1;     ///< capture every Nth frame
  std::string exportObjDirectory;  ///< OBJ frames of every cloth
  unsigned exportEvery = 1;      ///< export every Nth frame
  bool checkIntersections = false;  ///< count intersecting pairs each frame (not timed); exit 3 if any
  bool quiet = false;            ///< no progress output
  std::string summaryJson;       ///< write the report as JSON here
};

/// `weft bench SCENE`: repeated runs without rendering; per-frame simulation time statistics.
struct BenchOptions {
  std::string scene;
  long frames = -1;    ///< −1: the scene's run length, at most 120
  int repeats = 3;     ///< runs, each from a freshly built world
  int threads = 0;     ///< 0 = all cores
};

/// `weft validate SCENE...`: parse, check and build each scene; exit code 0 when all are valid.
struct ValidateOptions {
  std::vector<std::string> scenes;
};

int runScene(const RunOptions& options, std::ostream& out);
int benchScene(const BenchOptions& options, std::ostream& out);
int validateScenes(const ValidateOptions& options, std::ostream& out);

}  // namespace weft
