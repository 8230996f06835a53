// Stress scene 9 with the heavy objects as cloths of their own: two 0.5 kg pads dropped on a
// 0.15 kg sheet pinned at its corners, three cloths of one World, so the pads load the sheet
// through the contacts between cloths (all cloths of a World share one contact space) instead of
// the contacts of one cloth with itself. The same conditions as scene 9, and no intersecting pair
// between the cloths either.
#include "engine/ContactTestSupport.h"
#include "stress/StressSupport.h"

#include <limits>

namespace weft::stress {
namespace {

constexpr Real kFrame = 1.0 / 60.0;

using test::horizontalSquare;
using test::IntersectionCounter;

TEST(StressClothCloth, HeavyClothsDroppedOnASheetPinnedAtItsCorners) {
  constexpr Index kSheet = 15, kPad = 4;
  World world;
  const auto sheetModel = horizontalSquare(kSheet, 1.0, 1.0);
  const auto padModel = horizontalSquare(kPad, 0.12, 0.0);
  ClothSettings sheetSettings;
  sheetSettings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  // Pinned at its corners: the 2 × 2 vertices of each corner.
  for (Index row : {0u, 1u, kSheet - 2, kSheet - 1}) {
    for (Index column : {0u, 1u, kSheet - 2, kSheet - 1}) {
      sheetSettings.pinnedVertices.push_back(row * kSheet + column);
    }
  }
  const ClothId sheet = world.createCloth(sheetModel, sheetSettings).value();
  constexpr Real kObjectMass = 0.5;  // kg each; the sheet weighs 0.15 kg
  std::vector<ClothId> pads;
  for (const Vec3& centre : {Vec3(-0.2, 1.25, 0.1), Vec3(0.15, 1.4, -0.15)}) {
    ClothSettings padSettings;
    padSettings.material = cottonFabric();
    padSettings.vertexMasses.assign(kPad * kPad, kObjectMass / (kPad * kPad));
    padSettings.translation = centre;
    pads.push_back(world.createCloth(padModel, padSettings).value());
  }
  StressMonitor monitor(world);
  monitor.watch(sheet, *sheetModel);
  for (ClothId pad : pads) monitor.watch(pad, *padModel);
  IntersectionCounter between(world, {sheet, pads[0], pads[1]});
  Index worstBetween = 0;
  for (int frame = 0; frame < 150; ++frame) {
    if (!monitor.afterFrame(world.step(kFrame))) break;
    worstBetween = std::max(worstBetween, between.count(world));
  }
  // The objects landed and rest on the sheet: above its lowest vertex, not through it.
  Real lowestSheet = std::numeric_limits<Real>::infinity();
  for (const Vec3& x : world.positions(sheet).value()) lowestSheet = std::min(lowestSheet, x.y());
  const Real firstPad = world.positions(pads[0]).value()[0].y();
  const Real secondPad = world.positions(pads[1]).value()[0].y();
  std::printf("[stress] heavy cloths: pad corners at y = %.3f and %.3f, lowest sheet vertex %.3f, "
              "intersecting pairs between the cloths %u at most\n",
              firstPad, secondPad, lowestSheet, worstBetween);
  EXPECT_LT(firstPad, 1.25);
  EXPECT_GT(firstPad, lowestSheet);
  EXPECT_GT(secondPad, lowestSheet);
  EXPECT_EQ(worstBetween, 0u);
  EXPECT_GT(world.stats().clothContacts, 0u);
  // The projection holds the pairs between cloths and every cloth's strain limit together
  // (ContactProjector.h), so lifting the sheet lifts the pads with it.
  monitor.expectPasses("heavy_cloths_on_sheet", kCottonStrainLimit);
}

}  // namespace
}  // namespace weft::stress
