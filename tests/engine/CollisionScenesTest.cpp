// A cloth folding onto itself on the floor, two ways: folded in half by pins carried over it
// like a napkin, and dropped on a corner so that it crumples. In every frame no two triangles
// intersect (exact triangle–triangle test) and no vertex is inside the floor.
#include "ContactTestSupport.h"

#include <weft/collision/Plane.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace weft {
namespace {

using test::closestApproach;
using test::cornerDrop;
using test::horizontalSquare;
using test::IntersectionCounter;
using test::napkinFoldTargets;

constexpr Real kFrame = 1.0 / 60.0;
constexpr Index kSide = 15;  // vertices per side
constexpr Real kSize = 0.6;  // m

TEST(CollisionScenes, ANapkinFoldedInHalfOnTheFloor) {
  World world;
  const ColliderId floor = world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  // Row 0 is the edge at z = +0.3; its vertices are carried over the cloth to z = −0.3.
  ClothSettings settings;
  for (Index c = 0; c < kSide; ++c) settings.pinnedVertices.push_back(c);
  const ClothId cloth = world.createCloth(horizontalSquare(kSide, kSize, 0.01), settings).value();
  IntersectionCounter counter(world, {cloth});
  const std::vector<Vec3> start = world.pinTargets(cloth).value();
  constexpr int kFoldFrames = 90, kHoldFrames = 60;
  Index selfContacts = 0;
  for (int frame = 0; frame < kFoldFrames + kHoldFrames; ++frame) {
    // A half turn about the x axis through the middle, 2 cm above the floor at its end.
    const Real s = std::min<Real>(1, Real(frame + 1) / kFoldFrames);
    ASSERT_TRUE(world.setPinTargets(cloth, napkinFoldTargets(start, s, kSize)).ok());
    world.step(kFrame);
    selfContacts += world.stats().selfContacts;
    ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
    ASSERT_GE(closestApproach(world, cloth, floor), 0.0) << "a vertex is inside, frame " << frame;
  }
  // Folded: the carried edge lies over the far edge, the top half on the bottom half.
  const std::span<const Vec3> x = world.positions(cloth).value();
  const Vec3 carried = x[kSide / 2];
  const Vec3 far = x[(kSide - 1) * kSide + kSide / 2];
  EXPECT_LT(carried.z(), -0.2);
  EXPECT_GT(carried.y(), far.y() + ClothMaterial{}.thickness);
  EXPECT_GT(selfContacts, 100u);
  // The fold keeps the layers at least ~half a thickness apart where they lie on each other.
  EXPECT_GT(x[(kSide / 4) * kSide + kSide / 2].y(), x[(3 * kSide / 4) * kSide + kSide / 2].y());
}

TEST(CollisionScenes, AClothDroppedOnACornerCrumplesOnTheFloor) {
  World world;
  const ColliderId floor = world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  // Upright (turned a quarter about x), then a diamond (45° about z), so that it lands on one
  // corner from 30 cm: the lower part buckles and the rest falls onto it. (Tilted by 0.05 rad,
  // as first written, the cloth with isometric bending topples flat without touching itself.)
  const std::shared_ptr<const ClothModel> model = horizontalSquare(kSide, kSize, 0.0);
  // Its lowest vertex starts 30 cm above the floor.
  const ClothSettings settings = cornerDrop(*model, 0.3);
  const ClothId cloth = world.createCloth(model, settings).value();
  IntersectionCounter counter(world, {cloth});
  Index selfContacts = 0;
  for (int frame = 0; frame < 150; ++frame) {
    world.step(kFrame);
    selfContacts += world.stats().selfContacts + world.stats().selfImpacts;
    ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
    ASSERT_GE(closestApproach(world, cloth, floor), 0.0) << "a vertex is inside, frame " << frame;
  }
  // Down on the floor, lying on itself in places. How tall the pile stands is a chaotic outcome
  // held up by the floor's static friction (tests/README.md, "friction and the piles"): 7.9 … 23
  // cm at this frame over 16 drops from 27 to 31.7 cm, mean vertex height 2.6 … 11.5 cm. So this
  // asserts that the sheet came down instead of standing: its mean vertex height is below a
  // quarter of its side, where a sheet standing on an edge holds it at half its side. (Until
  // 2026-11-23 it asserted a highest vertex below 10 cm, met through the creep of the old friction
  // and a floor that gave way in the solve.)
  const std::span<const Vec3> x = world.positions(cloth).value();
  Real highest = 0;
  for (const Vec3& p : x) highest = std::max(highest, p.y());
  std::printf("[corner drop] highest vertex %.3f m, mean height %.3f m\n", highest,
              test::meanVertexHeight(x));
  EXPECT_LT(test::meanVertexHeight(x), kSize / 4);
  EXPECT_GT(selfContacts, 0u);
}

}  // namespace
}  // namespace weft
