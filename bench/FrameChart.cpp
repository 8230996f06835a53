#include "FrameChart.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <iomanip>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace weft {
namespace {

// gnuplot's path on PATH, or empty: a missing gnuplot is told apart from one that fails.
std::string findGnuplot() {
  const char* path = std::getenv("PATH");
  std::istringstream folders(path ? path : "/usr/bin:/bin");
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    const std::string candidate = (folder.empty() ? std::string(".") : folder) + "/gnuplot";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return {};
}

// A gnuplot single-quoted string: a quote inside is written twice.
std::string quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// "2.5", "16.7": a figure for a legend.
std::string figure(double value) {
  std::ostringstream text;
  text << std::setprecision(3) << value;
  return text.str();
}

// Absolute, so that the script can be rerun from any working directory.
std::string absolute(const std::string& path) {
  std::error_code error;
  const std::filesystem::path full = std::filesystem::absolute(path, error);
  return error ? path : full.lexically_normal().string();
}

std::string script(const FrameChartSettings& s) {
  std::ostringstream gp;
  gp << "# Per-frame times of a weft-curtain run; rerun with: gnuplot " << quoted(absolute(s.scriptPath))
     << "\nset terminal pngcairo size 1280,600 noenhanced font ',10'\n"
     << "set output " << quoted(absolute(s.pngPath)) << "\n"
     << "set datafile separator ','\n"
     << "set title " << quoted(s.title) << "\n"
     << "set xlabel 'frame (60 frames per simulated second)'\nset ylabel 'ms'\n"
     << "set xrange [1:" << std::max(2u, s.frames) << "]\nset yrange [0:*]\n"
     << "set grid ytics lc rgb '#d0d0d0'\nset key outside top center horizontal\n";
  // Phases: alternating bands behind the data, named at the top.
  for (std::size_t k = 0; k < s.phases.size(); ++k) {
    const ChartPhase& phase = s.phases[k];
    gp << "set object " << k + 1 << " rect from " << phase.beginFrame << ", graph 0 to "
       << phase.endFrame << ", graph 1 fc rgb '" << (k % 2 ? "#f2f2f2" : "#e4ecf7")
       << "' fs solid 1.0 noborder behind\n"
       << "set label " << k + 1 << " " << quoted(phase.name) << " at "
       << 0.5 * (phase.beginFrame + phase.endFrame) << ", graph 0.96 center font ',9'\n";
  }
  const std::string csv = quoted(absolute(s.csvPath));
  // Frame 1 pays for first touches of memory; the runner's statistics leave it out too. The
  // frame line goes first, so that simulation and render are drawn over it.
  gp << "plot ";
  if (s.rendering) {
    gp << csv << " every ::1 using 'frame':'frame_ms' with lines lw 0.8 lc rgb '#909090' "
          "title 'frame (loop iteration)', \\\n     "
       << csv << " every ::1 using 'frame':'render_ms' with lines lw 1.2 lc rgb '#e07b00' "
          "title 'render + read back', \\\n     ";
  }
  gp << csv << " every ::1 using 'frame':'sim_ms' with lines lw 1.2 lc rgb '#1f5fbf' "
        "title 'simulation'";
  gp << ", \\\n     1000.0 / 60 with lines dt 2 lw 1.5 lc rgb '#c00000' title '60 fps (16.7 ms)'";
  if (s.budgetMs > 0) {
    gp << ", \\\n     " << s.budgetMs << " with lines dt 3 lw 1.5 lc rgb '#6a3d9a' title "
       << quoted("budget (" + figure(s.budgetMs) + " ms)");
  }
  if (s.targetMs > 0) {
    gp << ", \\\n     " << s.targetMs << " with lines dt 4 lw 1.5 lc rgb '#2c8c2c' title "
       << quoted("simulation target (" + figure(s.targetMs) + " ms)");
  }
  gp << "\n";
  return gp.str();
}

}  // namespace

FrameChartOutcome writeFrameChart(const FrameChartSettings& settings) {
  FrameChartOutcome outcome;
  const std::string gnuplot = findGnuplot();
  if (gnuplot.empty()) {
    outcome.skipped = true;
    outcome.message = "gnuplot is not installed (apt-get install gnuplot-nox); the CSV has every figure";
    return outcome;
  }
  {
    std::ofstream file(settings.scriptPath);
    file << script(settings);
    if (!file) {
      outcome.message = "cannot write the chart script '" + settings.scriptPath +
                        "'; check that the directory is writable";
      return outcome;
    }
  }
  std::string scriptPath = settings.scriptPath;
  char* argv[] = {const_cast<char*>("gnuplot"), scriptPath.data(), nullptr};
  pid_t child = 0;
  if (const int error = ::posix_spawn(&child, gnuplot.c_str(), nullptr, nullptr, argv, environ)) {
    outcome.message = "cannot start " + gnuplot + " (error " + std::to_string(error) + ")";
    return outcome;
  }
  int status = 0;
  while (::waitpid(child, &status, 0) < 0) {
    if (errno != EINTR) {
      outcome.message = "lost track of gnuplot while it drew " + settings.pngPath;
      return outcome;
    }
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    outcome.message = "gnuplot failed on " + settings.scriptPath + " (exit status " +
                      std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
    return outcome;
  }
  outcome.written = true;
  return outcome;
}

}  // namespace weft
