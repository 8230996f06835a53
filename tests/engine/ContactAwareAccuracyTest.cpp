// Contact-aware accuracy (SolverSettings::tightCgTolerance, issue 7): the implicit solve runs at
// the loose default (velocity error 1e-1) until a substep is hard, jammed in self-contact or yanked
// by its pins, and then at the relative residual 1e-3. Seen from outside through the last solve's
// relative residual (StepStats::cgResidual): at most tightCgTolerance in hard frames, larger in
// the same frames with the tightening off, and larger in a free swing.
#include "ContactTestSupport.h"

#include <weft/collision/Plane.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace weft {
namespace {

using test::cornerDrop;
using test::horizontalSquare;

constexpr Real kFrame = 1.0 / 60.0;
constexpr Index kSide = 15;  // vertices per side
constexpr Real kSize = 0.6;  // m

// The corner drop of CollisionScenes.AClothDroppedOnACornerCrumplesOnTheFloor: a diamond
// upright on one corner 30 cm above the floor, which buckles into a pile on the floor.
struct CornerDrop {
  World world;
  ClothId cloth;
  explicit CornerDrop(const SolverSettings& solver) {
    (void)world.addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
    const std::shared_ptr<const ClothModel> model = horizontalSquare(kSide, kSize, 0.0);
    ClothSettings settings = cornerDrop(*model, 0.3);
    settings.solver = solver;
    cloth = world.createCloth(model, settings).value();
  }
};

TEST(ContactAwareAccuracy, AClothJammedInSelfContactSolvesTightly) {
  const SolverSettings defaults;
  SolverSettings untightened;
  untightened.tightCgTolerance = 0;
  CornerDrop tight(defaults), loose(untightened);
  Real tightWorst = 0, looseWorst = 0;
  Index jammedFrames = 0;
  test::StepHealth tightHealth, looseHealth;
  for (int frame = 0; frame < 150; ++frame) {
    tightHealth(tight.world.step(kFrame));
    looseHealth(loose.world.step(kFrame));
    // A frame after one whose self passes found many contacts per vertex is jammed (the stats
    // count every pass of the frame, at least the first one's contacts).
    const StepStats& stats = tight.world.stats();
    const Real density = Real(stats.selfContacts + stats.selfImpacts) / Real(kSide * kSide);
    if (frame >= 60 && density >= 4 * defaults.tightSelfContactDensity) {
      ++jammedFrames;
      tightWorst = std::max(tightWorst, stats.cgResidual);
      looseWorst = std::max(looseWorst, loose.world.stats().cgResidual);
    }
  }
  std::printf("[contact-aware] corner drop, %d jammed frames from frame 60: worst residual %.3g "
              "tightened, %.3g not\n",
              int(jammedFrames), tightWorst, looseWorst);
  tightHealth.expectHealthy("corner drop, tightened");
  looseHealth.expectHealthy("corner drop, not tightened");
  ASSERT_GT(jammedFrames, 20);  // the pile forms and stays in self-contact
  EXPECT_LE(tightWorst, defaults.tightCgTolerance);
  EXPECT_GT(looseWorst, 10 * defaults.tightCgTolerance);
}

// A sheet hanging from its top row; with pinTeleportDistance off, pins that jump 10 m drag it.
struct HangingSheet {
  World world;
  ClothId cloth;
  explicit HangingSheet(const SolverSettings& solver) {
    ClothSettings settings;
    settings.solver = solver;
    settings.solver.pinTeleportDistance = 0;
    settings.sleep.enabled = false;
    for (Index c = 0; c < kSide; ++c) settings.pinnedVertices.push_back(c);
    const Mat3 upright = Eigen::AngleAxis<Real>(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
    settings.rotation = upright;
    settings.translation = Vec3(0, 1.5, 0);
    cloth = world.createCloth(horizontalSquare(kSide, kSize, 0.0), settings).value();
  }
};

TEST(ContactAwareAccuracy, PinsYankedFarInASubstepMakeItHardAndAFreeSwingStaysLoose) {
  const SolverSettings defaults;
  SolverSettings untightened;
  untightened.tightCgTolerance = 0;
  HangingSheet tight(defaults), loose(untightened);
  // A free swing from the flat start: loose solves in both.
  Real swingResidual = 0;
  for (int frame = 0; frame < 20; ++frame) {
    tight.world.step(kFrame);
    loose.world.step(kFrame);
    EXPECT_EQ(tight.world.stateHash(), loose.world.stateHash()) << "frame " << frame;
    swingResidual = std::max(swingResidual, tight.world.stats().cgResidual);
  }
  // The yank: every pin 10 m along x in one frame, about one mean edge per automatic substep.
  for (HangingSheet* sheet : {&tight, &loose}) {
    std::vector<Vec3> targets = sheet->world.pinTargets(sheet->cloth).value();
    for (Vec3& target : targets) target.x() += 10;
    ASSERT_TRUE(sheet->world.setPinTargets(sheet->cloth, targets).ok());
    sheet->world.step(kFrame);
  }
  std::printf("[contact-aware] hanging sheet: swing residual %.3g; yank (%d substeps) %.3g "
              "tightened, %.3g not\n",
              swingResidual, int(tight.world.stats().substeps), tight.world.stats().cgResidual,
              loose.world.stats().cgResidual);
  EXPECT_GT(tight.world.stats().substeps, 100);
  EXPECT_GT(swingResidual, 10 * defaults.tightCgTolerance);
  EXPECT_LE(tight.world.stats().cgResidual, defaults.tightCgTolerance);
  EXPECT_GT(loose.world.stats().cgResidual, 10 * defaults.tightCgTolerance);
}

}  // namespace
}  // namespace weft
