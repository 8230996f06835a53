// Self-contacts inside the implicit solve (SolverSettings::selfContactStiffness): the corner
// crumple of CollisionScenesTest settles at a tight solver tolerance, a napkin folded by its pins
// stays untangled whatever the solve's form, and the pile is bitwise identical on one and two
// threads.
#include "ContactTestSupport.h"

#include <weft/collision/Plane.h>
#include <weft/engine/FabricPresets.h>
#include <weft/threading/TaskSystem.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace weft {
namespace {

using test::closestApproach;
using test::cornerDrop;
using test::horizontalSquare;
using test::IntersectionCounter;
using test::napkinFoldTargets;

constexpr Real kFrame = 1.0 / 60.0;

// The corner crumple of CollisionScenesTest at cgTolerance 1e-4 (relative residual), over eight
// drop heights (27 to 31.7 cm; the pile is a chaotic outcome of the drop). Without self-contacts
// in the solve such piles keep stirring (tests/README.md, "The crumpled piles"); with them
// (stiffness 1, contact/SelfContactPenalty.h) each draw must settle: kinetic energy below 1e-5 J after 400
// frames. Every draw also asserts no intersecting pair and no vertex in the floor after every
// frame, that the cloth lay on itself and came down, the strain condition (cotton: the limit +
// 0.01), and no rollback or retry. The parameter is the drop height (m).
class SelfContactSolvePile : public ::testing::TestWithParam<Real> {};

TEST_P(SelfContactSolvePile, ACrumpledPileSettlesAtATightSolverTolerance) {
  const Real lift = GetParam();
  constexpr Real kSize = 0.6;  // m
  const std::shared_ptr<const ClothModel> model = horizontalSquare(15, kSize, 0.0);
  World world;
  const ColliderId floor = world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  ClothSettings settings = cornerDrop(*model, lift);
  settings.material = cottonFabric();
  settings.solver.cgTolerance = 1e-4;
  settings.solver.selfContactStiffness = 1;
  const ClothId cloth = world.createCloth(model, settings).value();
  IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  Index selfContacts = 0;
  Real maxStrain = 0;
  for (int frame = 0; frame < 400; ++frame) {
    health(world.step(kFrame));
    selfContacts += world.stats().selfContacts;
    maxStrain = std::max(maxStrain, world.stats().maxStrain);
    // The self-collision pass still has the last word: nothing crosses, nothing is inside.
    ASSERT_EQ(counter.count(world), 0u) << "frame " << frame;
    ASSERT_GE(closestApproach(world, cloth, floor), 0.0) << "frame " << frame;
  }
  const std::span<const Vec3> x = world.positions(cloth).value();
  const Real energy = world.stats().kineticEnergy;
  std::printf("[pile] from %.3f m: kinetic energy %.3g J after 400 frames, mean height %.3f m, "
              "max strain %.4f, self-contacts %u\n", lift, energy, test::meanVertexHeight(x),
              maxStrain, unsigned(selfContacts));
  EXPECT_GT(selfContacts, 1000u) << "the cloth did not lie on itself";
  // Down, not standing (CollisionScenesDrop): a sheet standing on an edge holds its mean vertex
  // height at half its side.
  EXPECT_LT(test::meanVertexHeight(x), kSize / 4);
  EXPECT_LE(maxStrain, settings.material.strainLimit + 0.01);
  health.expectHealthy("pile");
  EXPECT_LT(energy, 1e-5) << "still stirring";
}

INSTANTIATE_TEST_SUITE_P(
    Heights, SelfContactSolvePile,
    ::testing::Values(0.270, 0.277, 0.284, 0.291, 0.300, 0.302, 0.310, 0.317),
    [](const ::testing::TestParamInfo<Real>& info) {
      return std::string("from_").append(std::to_string(std::lround(info.param * 1000))).append("_mm");
    });

TEST(SelfContactSolve, ANapkinFoldedByItsPinsStaysUntangledWithPinsRemovedKeptOrNewton) {
  // The napkin of CollisionScenesTest: row 0 pinned and carried over the cloth onto it, so pinned
  // vertices are in self-contact pairs: their known Δv goes to the right-hand side when the pins
  // are removed from the solve, and they are filtered rows when kept; a Newton iteration
  // linearises the terms again at its iterate.
  constexpr Index kSide = 15;
  constexpr Real kSize = 0.6;
  struct Variant {
    bool removePins;
    int newtonIterations;
  };
  for (const Variant variant : {Variant{true, 0}, Variant{false, 0}, Variant{true, 1}}) {
    World world;
    const ColliderId floor = world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
    ClothSettings settings;
    settings.material = cottonFabric();  // so that the strain condition applies
    for (Index c = 0; c < kSide; ++c) settings.pinnedVertices.push_back(c);
    settings.solver.selfContactStiffness = 1;
    settings.solver.removePinnedVertices = variant.removePins;
    settings.solver.newtonIterations = variant.newtonIterations;
    const ClothId cloth = world.createCloth(horizontalSquare(kSide, kSize, 0.01), settings).value();
    IntersectionCounter counter(world, {cloth});
    const std::vector<Vec3> start = world.pinTargets(cloth).value();
    constexpr int kFoldFrames = 90, kHoldFrames = 60;
    Index selfContacts = 0;
    test::StepHealth health;
    Real maxStrain = 0;
    for (int frame = 0; frame < kFoldFrames + kHoldFrames; ++frame) {
      const Real s = std::min<Real>(1, Real(frame + 1) / kFoldFrames);
      ASSERT_TRUE(world.setPinTargets(cloth, napkinFoldTargets(start, s, kSize)).ok());
      health(world.step(kFrame));
      selfContacts += world.stats().selfContacts;
      ASSERT_EQ(counter.count(world), 0u) << "removePins " << variant.removePins << ", Newton "
                                          << variant.newtonIterations << ", frame " << frame;
      ASSERT_GE(closestApproach(world, cloth, floor), 0.0) << "frame " << frame;
      maxStrain = std::max(maxStrain, world.stats().maxStrain);
    }
    health.expectHealthy("napkin");
    EXPECT_GT(selfContacts, 100u);
    // Folded: the carried edge over the far one, the top half on the bottom half, above it.
    const std::span<const Vec3> x = world.positions(cloth).value();
    EXPECT_LT(x[kSide / 2].z(), -0.2);
    EXPECT_GT(x[kSide / 2].y(), x[(kSide - 1) * kSide + kSide / 2].y() + ClothMaterial{}.thickness);
    // Where the carried half lies over the other (the middle column, within half an edge in z), it
    // is the upper layer. Which rows meet is chaotic: the half may land folded again (an S), so
    // no row pairing is asserted, only the order of the layers, and that they do overlap.
    const Real halfEdge = 0.5 * kSize / Real(kSide - 1);
    int stacked = 0;
    for (Index top = 1; top < kSide / 2; ++top) {
      const Vec3& upper = x[top * kSide + kSide / 2];
      for (Index bottom = kSide / 2 + 1; bottom < kSide; ++bottom) {
        const Vec3& lower = x[bottom * kSide + kSide / 2];
        if (std::abs(upper.z() - lower.z()) > halfEdge || std::abs(upper.y() - lower.y()) > 0.05) continue;
        EXPECT_GT(upper.y(), lower.y()) << "row " << top << " under row " << bottom;
        ++stacked;
      }
    }
    EXPECT_GE(stacked, 2) << "the carried half does not lie on the other";
    std::printf("[napkin] removePins %d, Newton %d: max strain %.4f\n", int(variant.removePins),
                variant.newtonIterations, maxStrain);
    EXPECT_LE(maxStrain, settings.material.strainLimit + 0.01) << "in some frame";
  }
}

TEST(SelfContactSolve, ThePileIsBitwiseIdenticalOnOneAndTwoThreads) {
  // The couplings are applied serially in pair order and the active set is decided per pair:
  // the contract of DeterminismTest holds with them.
  const std::shared_ptr<const ClothModel> model = horizontalSquare(15, 0.6, 0.0);
  std::vector<std::uint64_t> hashes[2];
  for (int threads : {1, 2}) {
    TaskSystem tasks(TaskSystemSettings{threads});
    WorldSettings worldSettings;
    worldSettings.taskSystem = &tasks;
    World world(worldSettings);
    (void)world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
    ClothSettings settings = cornerDrop(*model, 0.3);
    settings.solver.selfContactStiffness = 1;
    (void)world.createCloth(model, settings).value();
    Index selfContacts = 0;
    test::StepHealth health;
    for (int frame = 0; frame < 120; ++frame) {
      health(world.step(kFrame));
      selfContacts += world.stats().selfContacts;
      hashes[threads - 1].push_back(world.stateHash());
    }
    EXPECT_GT(selfContacts, 100u);
    health.expectHealthy("pile on " + std::to_string(threads) + " threads");
  }
  for (std::size_t frame = 0; frame < hashes[0].size(); ++frame) {
    ASSERT_EQ(hashes[1][frame], hashes[0][frame]) << "first difference at frame " << frame + 1;
  }
}

}  // namespace
}  // namespace weft
