// GameLoop: how a game drives Weft. The display runs at whatever rate it gets; the simulation
// runs at a fixed 60 Hz, fed by an accumulator ("Fix Your Timestep", Glenn Fiedler 2004):
//
//   every display frame:  steps = accumulator.advance(frame time)     (weft::FixedStepAccumulator)
//                         repeat steps times:  move the pins, World::step(1/60 s)
//                         draw: blend the last two simulation states by accumulator.alpha()
//
// A fixed step keeps the simulation independent of the frame rate: the same inputs give the same
// bits whether the game draws at 40 or 140 Hz, and the solver never sees a step longer than the
// one it was tuned for. Here the "display" frame times are a pseudo-random 7–25 ms sequence from
// a fixed seed, so the output (state hash included) is the same on every run and thread count.
// A game short of time would call World::step(dt, StepBudget{.milliseconds = 4}) instead: the
// engine then plans each step from measured costs, which makes the bits depend on the machine's
// load (the plans it ran are in StepStats::plan, and World::step(dt, plan) replays them exactly).
// This example keeps the fixed settings so that its output is reproducible.
//
// The cloth is a 21×15 sheet held out level from a rod along one edge: it falls, swings down and
// hangs, while the rod sways side to side and the pinned edge follows it (World::setPinTargets).
// Each display frame reads the render view (positions, normals, indices) as a renderer would,
// and every 10th prints a short summary.
//
//   weft-example-game-loop [display frames = 120]
#include <weft/Weft.h>

#include <algorithm>
#include <charconv>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <vector>

namespace {

constexpr double kSimulationDt = 1.0 / 60.0;  // s, the fixed simulation step
// At most this many simulation steps per display frame: after a long stall (a debugger, a slow
// load) the game slows down instead of spending ever longer frames catching up.
constexpr int kMaxStepsPerDisplayFrame = 4;
constexpr double kRodAmplitude = 0.25;  // m, how far the rod sways either side
constexpr double kRodPeriod = 2.0;      // s, one full sway

// Display frame times of 7–25 ms from a fixed seed. The arithmetic of std::minstd_rand is fixed
// by the standard but the distributions are not, so the range mapping is done by hand.
class FrameTimeSequence {
 public:
  double next() {
    m_state = (m_state * 48271u) % 2147483647u;
    return (7.0 + static_cast<double>(m_state % 19u)) / 1000.0;
  }

 private:
  std::uint64_t m_state = 20240601u;
};

// x offset of the rod (m) at time t (s).
double rodOffset(double t) {
  return kRodAmplitude * std::sin(2.0 * std::numbers::pi * t / kRodPeriod);
}

int parseFrames(int argc, char** argv) {
  if (argc < 2) return 120;
  int frames = 0;
  const char* end = argv[1] + std::strlen(argv[1]);
  const auto [ptr, ec] = std::from_chars(argv[1], end, frames);
  if (ec != std::errc{} || ptr != end || frames <= 0) return -1;
  return frames;
}

}  // namespace

int main(int argc, char** argv) {
  const int displayFrames = parseFrames(argc, argv);
  if (displayFrames < 0) {
    std::fprintf(stderr, "usage: %s [display frames > 0, default 120]\n", argv[0]);
    return 2;
  }

  // 1 m × 0.7 m, level at y = 2 m: columns along x, rows along +z away from the rod at z = 0.
  weft::GridSettings grid;
  grid.columns = 21;
  grid.rows = 15;
  grid.width = 1.0;
  grid.height = 0.7;
  grid.origin = weft::Vec3(-0.5, 2.0, 0.0);
  grid.heightAxis = weft::Vec3(0.0, 0.0, 1.0);
  auto model = weft::ClothModel::grid(grid);
  if (!model) {
    std::fprintf(stderr, "game-loop: %s\n", model.error().message.c_str());
    return 1;
  }
  auto shared = std::make_shared<const weft::ClothModel>(std::move(model).value());

  // Pin row 0 (the edge on the rod) and remember where each pin sits on the rod.
  weft::ClothSettings settings;
  std::vector<weft::Vec3> rodPoints;
  for (weft::Index column = 0; column < grid.columns; ++column) {
    const weft::Index vertex = column;
    settings.pinnedVertices.push_back(vertex);
    rodPoints.push_back(shared->restPositions()[vertex]);
  }

  weft::World world;
  auto created = world.createCloth(shared, settings);
  if (!created) {
    std::fprintf(stderr, "game-loop: %s\n", created.error().message.c_str());
    return 1;
  }
  const weft::ClothId cloth = created.value();

  weft::FixedStepAccumulator accumulator(kSimulationDt, kMaxStepsPerDisplayFrame);

  FrameTimeSequence frameTimes;
  std::vector<weft::Vec3> pinTargets(rodPoints.size());
  // The state before the latest step: drawing blends it with the current one by alpha().
  std::vector<weft::Vec3> previous(shared->restPositions().begin(), shared->restPositions().end());
  double displayTime = 0;
  long simulationSteps = 0;
  int notConverged = 0;

  std::printf("game-loop: %u vertices, %u triangles, %d display frames, simulation at %.0f Hz\n",
              static_cast<unsigned>(shared->vertexCount()),
              static_cast<unsigned>(shared->triangleCount()), displayFrames, 1.0 / kSimulationDt);

  for (int frame = 1; frame <= displayFrames; ++frame) {
    const double frameTime = frameTimes.next();
    displayTime += frameTime;
    const int steps = accumulator.advance(frameTime);

    for (int step = 0; step < steps; ++step) {
      // Pin targets are where the pins are at the end of the coming step; the world moves them
      // there linearly across it.
      const double endTime = world.time() + kSimulationDt;
      for (std::size_t i = 0; i < rodPoints.size(); ++i) {
        pinTargets[i] = rodPoints[i] + weft::Vec3(rodOffset(endTime), 0.0, 0.0);
      }
      if (weft::Status moved = world.setPinTargets(cloth, pinTargets); !moved) {
        std::fprintf(stderr, "game-loop: %s\n", moved.error().message.c_str());
        return 1;
      }
      if (step == steps - 1) {
        // Only the state before the last step of this frame is blended with, so copy just that.
        auto current = world.positions(cloth);
        if (current) previous.assign(current->begin(), current->end());
      }
      const weft::StepStatus status = world.step(accumulator.step());
      ++simulationSteps;
      if (weft::hasFlag(status, weft::StepStatus::RolledBack) ||
          weft::hasFlag(status, weft::StepStatus::InvalidInput)) {
        std::fprintf(stderr, "game-loop: step %ld: %s\n", simulationSteps,
                     weft::describe(status).c_str());
        return 1;
      }
      if (weft::hasFlag(status, weft::StepStatus::SolverNotConverged)) ++notConverged;
    }

    // "Draw": read the render view as a renderer would and blend positions by alpha. The spans
    // stay valid until the next step(), which is all a frame needs.
    auto view = world.renderView(cloth);
    if (!view) {
      std::fprintf(stderr, "game-loop: %s\n", view.error().message.c_str());
      return 1;
    }
    const double alpha = accumulator.alpha();
    weft::Vec3 centroid = weft::Vec3::Zero();
    double lowest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < view->positions.size(); ++i) {
      const weft::Vec3 drawn = (1.0 - alpha) * previous[i] + alpha * view->positions[i];
      if (!weft::isFinite(drawn)) {
        std::fprintf(stderr, "game-loop: non-finite position at vertex %zu\n", i);
        return 1;
      }
      centroid += drawn;
      lowest = std::min(lowest, drawn.y());
    }
    centroid /= static_cast<double>(view->positions.size());

    if (frame % 10 == 0 || frame == displayFrames) {
      std::printf("frame %4d  display %6.3f s  sim %6.3f s  steps %d  alpha %.2f  centroid "
                  "(%+.3f, %.3f, %+.3f)  lowest y %.3f  %zu normals  %zu triangles\n",
                  frame, displayTime, world.time(), steps, alpha, centroid.x(), centroid.y(),
                  centroid.z(), lowest, view->normals.size(), view->indices.size() / 3);
    }
  }

  std::printf("game-loop: ok, %d display frames, %ld simulation steps (%llu dropped after "
              "stalls), %d not converged, max strain %.4f, state hash %016" PRIx64 "\n",
              displayFrames, simulationSteps,
              static_cast<unsigned long long>(accumulator.droppedSteps()), notConverged,
              world.stats().maxStrain, world.stateHash());
  return 0;
}
