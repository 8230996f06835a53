// Pinned vertices removed from the implicit solve (SolverSettings::removePinnedVertices): the
// system shrinks by one row per pin, the known velocity change of moving pins reaches their free
// neighbours through the right-hand side, and the motion matches the old filtered solve (pins
// kept in the system with S = 0) to the accuracy of the linear solve. Bitwise deterministic for
// any thread count.
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace weft {
namespace {

constexpr Index kColumns = 21, kRows = 15;

std::shared_ptr<const ClothModel> flagModel() {
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 0.6;
  grid.height = 0.4;
  grid.origin = Vec3(0, 1, 0);
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

// A flag held on two edges: the pole (left column) and the top row.
std::vector<Index> twoEdges() {
  std::vector<Index> pins;
  for (Index r = 0; r < kRows; ++r) pins.push_back(r * kColumns);
  for (Index c = 1; c < kColumns; ++c) pins.push_back((kRows - 1) * kColumns + c);
  return pins;
}

struct Flag {
  std::unique_ptr<World> world;
  ClothId cloth;
  std::vector<Vec3> rest;  // pin targets at the start
};

Flag makeFlag(bool removePins, int threads, Real cgTolerance) {
  WorldSettings worldSettings;
  worldSettings.threadCount = threads;
  Flag flag;
  flag.world = std::make_unique<World>(worldSettings);
  ClothSettings settings;
  settings.pinnedVertices = twoEdges();
  settings.solver.removePinnedVertices = removePins;
  settings.solver.cgTolerance = cgTolerance;
  settings.solver.cgMaxIterations = 2000;
  settings.sleep.enabled = false;
  settings.selfCollision = false;  // the solve is what is compared here
  flag.cloth = flag.world->createCloth(flagModel(), settings).value();
  flag.rest = flag.world->pinTargets(flag.cloth).value();
  return flag;
}

// Moves the pins: the pole sways along z and the top edge is pulled up and down, so the pins'
// velocity changes every frame (the case where their Δv is not zero).
void stepFlag(Flag& flag, int frame) {
  const Real t = (frame + 1) / 60.0;
  std::vector<Vec3> targets = flag.rest;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    targets[k].z() += 0.05 * std::sin(6 * t);
    targets[k].y() += 0.02 * std::sin(9 * t) * (targets[k].x() / 0.6);
  }
  ASSERT_TRUE(flag.world->setPinTargets(flag.cloth, targets).ok());
  flag.world->step(1.0 / 60);
}

Real maxDistance(const Flag& a, const Flag& b) {
  const auto x = a.world->positions(a.cloth).value();
  const auto y = b.world->positions(b.cloth).value();
  Real distance = 0;
  for (std::size_t i = 0; i < x.size(); ++i) distance = std::max(distance, (x[i] - y[i]).norm());
  return distance;
}

TEST(PinRemoval, MovingPinsGiveTheFilteredSolveWithinTheSolveTolerance) {
  const Index vertices = kColumns * kRows;
  const Index pins = Index(twoEdges().size());
  // A tight solve: both paths then solve the same equations to ~1e-10, and the remaining
  // difference is round-off carried through 40 frames.
  Flag removed = makeFlag(true, 1, 1e-10), filtered = makeFlag(false, 1, 1e-10);
  Real largest = 0;
  for (int frame = 0; frame < 40; ++frame) {
    stepFlag(removed, frame);
    stepFlag(filtered, frame);
    largest = std::max(largest, maxDistance(removed, filtered));
    EXPECT_EQ(removed.world->stats().solvedUnknowns, 3 * (vertices - pins));
    EXPECT_EQ(filtered.world->stats().solvedUnknowns, 3 * vertices);
  }
  // The flag moved by centimetres; the two solves agree to 1e-8 m (measured 1.4e-9 m): the
  // 1e-10 residual of each solve, carried through 40 frames.
  EXPECT_LT(largest, 1e-8) << "largest vertex distance " << largest << " m";
  const auto x = removed.world->positions(removed.cloth).value();
  Real travel = 0;
  for (Index i = 0; i < vertices; ++i) {
    travel = std::max(travel, (x[i] - flagModel()->restPositions()[i] - Vec3(0, 1, 0)).norm());
  }
  EXPECT_GT(travel, 0.02);

  // At the default tolerance (1e-3 relative residual) too: in exact arithmetic the two run the
  // same CG iterates (a filtered row adds zeros to every dot product and search direction), so
  // they differ by round-off only (measured 1e-12 m; more iterations carry more of it).
  Flag removedDefault = makeFlag(true, 1, 1e-3), filteredDefault = makeFlag(false, 1, 1e-3);
  Real largestDefault = 0;
  for (int frame = 0; frame < 40; ++frame) {
    stepFlag(removedDefault, frame);
    stepFlag(filteredDefault, frame);
    largestDefault = std::max(largestDefault, maxDistance(removedDefault, filteredDefault));
  }
  std::printf("removed vs filtered pins, 40 frames: %.2e m at tolerance 1e-10, %.2e m at 1e-3\n",
              largest, largestDefault);
  EXPECT_LT(largestDefault, 1e-9) << "largest vertex distance " << largestDefault << " m";
  // Pins land exactly on their targets on both paths.
  const auto targets = removedDefault.world->pinTargets(removedDefault.cloth).value();
  const auto positions = removedDefault.world->positions(removedDefault.cloth).value();
  const std::vector<Index> pinList = twoEdges();
  for (std::size_t k = 0; k < pinList.size(); ++k) EXPECT_EQ(positions[pinList[k]], targets[k]);
}

TEST(PinRemoval, OneAndTwoThreadsGiveTheSameBits) {
  Flag one = makeFlag(true, 1, 1e-3), two = makeFlag(true, 2, 1e-3);
  for (int frame = 0; frame < 30; ++frame) {
    stepFlag(one, frame);
    stepFlag(two, frame);
    ASSERT_EQ(one.world->stateHash(), two.world->stateHash()) << "frame " << frame + 1;
  }
}

TEST(PinRemoval, PinsMovingWithTheClothLeaveItRigid) {
  // Zero gravity, no air: a cloth moving at u with pins moving at u is at equilibrium, so the
  // solve must give Δv = 0 for every free vertex (the pins' Δv is zero too after the first step).
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  worldSettings.gravity = Vec3::Zero();
  World world(worldSettings);
  ClothSettings settings;
  settings.pinnedVertices = twoEdges();
  settings.material.airDrag = 0;
  settings.sleep.enabled = false;
  settings.selfCollision = false;
  const ClothId cloth = world.createCloth(flagModel(), settings).value();
  const Vec3 velocity(0.3, -0.1, 0.2);
  const auto start = world.positions(cloth).value();
  const std::vector<Vec3> startPositions(start.begin(), start.end());
  ASSERT_TRUE(
      world.setState(cloth, startPositions, std::vector<Vec3>(startPositions.size(), velocity)).ok());
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (int frame = 1; frame <= 20; ++frame) {
    for (Vec3& target : targets) target += velocity / 60.0;
    ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
    world.step(1.0 / 60);
  }
  const auto positions = world.positions(cloth).value();
  Real deviation = 0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    deviation = std::max(deviation, (positions[i] - startPositions[i] - velocity * (20 / 60.0)).norm());
  }
  EXPECT_LT(deviation, 1e-9);
}

}  // namespace
}  // namespace weft
