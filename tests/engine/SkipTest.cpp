// Skips of stages a scene does not need (WorldSettings::skipUnneededStages): each skip must take
// effect where it applies (its counter in StepStats reads zero runs) and must not change a bit of
// the result compared with the same scene run with every stage forced on.
#include "FoldCulling.h"

#include <weft/engine/World.h>
#include <weft/scenes/Curtain.h>

#include <gtest/gtest.h>

#include <weft/collision/Plane.h>

#include <cmath>
#include <cstdio>
#include <memory>

namespace weft {
namespace {

std::shared_ptr<const ClothModel> grid(Index columns, Index rows, Real width, Real height) {
  GridSettings settings;
  settings.columns = columns;
  settings.rows = rows;
  settings.width = width;
  settings.height = height;
  return std::make_shared<const ClothModel>(ClothModel::grid(settings).value());
}

ClothSettings pinnedTopRow(Index columns, Index rows) {
  ClothSettings settings;
  for (Index c = 0; c < columns; ++c) settings.pinnedVertices.push_back((rows - 1) * columns + c);
  return settings;
}

CurtainScene curtain(bool skips) {
  CurtainSettings settings;
  settings.skipUnneededStages = skips;
  settings.sleep = false;  // sleeping has its own tests
  settings.threadCount = 1;
  return CurtainScene::create(settings).value();
}

TEST(Skip, CurtainSkipsFarCollidersAndTheFlatSelfPassWithTheSameBits) {
  CurtainScene skipping = curtain(true), full = curtain(false);
  // 0–1 s the curtain settles: the sphere (0.25 m behind it) and the floor (0.5 m below it) are
  // far, and the curtain hangs nearly flat. 1–1.6 s the sphere pushes in: its narrow phase runs,
  // the floor's stays skipped.
  Index settlingNarrow = 0, settlingSkipped = 0, settlingSelf = 0, settlingSelfSkipped = 0;
  Index pushNarrow = 0, pushSkipped = 0;
  for (int frame = 0; frame < 100; ++frame) {
    skipping.stepFrame();
    full.stepFrame();
    ASSERT_EQ(skipping.world().stateHash(), full.world().stateHash()) << "frame " << frame + 1;
    const StepStats& s = skipping.world().stats();
    const StepStats& f = full.world().stats();
    EXPECT_EQ(f.colliderNarrowPhasesSkipped, 0u);
    EXPECT_EQ(f.selfCollisionSkipped, 0u);
    EXPECT_EQ(s.colliderNarrowPhases + s.colliderNarrowPhasesSkipped, f.colliderNarrowPhases);
    if (frame < 55) {
      settlingNarrow += s.colliderNarrowPhases;
      settlingSkipped += s.colliderNarrowPhasesSkipped;
      settlingSelf += s.selfCollisionPasses;
      settlingSelfSkipped += s.selfCollisionSkipped;
    } else if (frame >= 80) {
      pushNarrow += s.colliderNarrowPhases;
      pushSkipped += s.colliderNarrowPhasesSkipped;
    }
  }
  EXPECT_EQ(settlingNarrow, 0u);
  EXPECT_GT(settlingSkipped, 0u);
  EXPECT_EQ(settlingSelf, 0u);
  EXPECT_EQ(settlingSelfSkipped, 55u);  // one substep per frame
  // During the push the sphere is tested (constraint and response passes), the floor is not.
  EXPECT_GT(pushNarrow, 0u);
  EXPECT_GE(pushSkipped, 40u);  // the floor: 2 passes × 20 frames
  EXPECT_GT(skipping.world().stats().contacts, 0u);
}

TEST(Skip, ZeroBendingAndZeroDampingAreNotAssembled) {
  const Index columns = 9, rows = 7;
  auto model = grid(columns, rows, 0.4, 0.3);
  ClothSettings settings = pinnedTopRow(columns, rows);
  settings.material.bendingStiffness = 0;
  settings.material.bendingDamping = 0;
  settings.material.stretchDamping = 0;
  settings.material.shearDamping = 0;
  settings.sleep.enabled = false;
  WorldSettings skipping, full;
  skipping.threadCount = full.threadCount = 1;
  full.skipUnneededStages = false;
  World a(skipping), b(full);
  const ClothId clothA = a.createCloth(model, settings).value();
  const ClothId clothB = b.createCloth(model, settings).value();
  // A swinging start, so that every term has work: the cloth is pushed sideways.
  std::vector<Vec3> velocities(model->vertexCount(), Vec3(0.3, 0, 0.5));
  const auto positions = a.positions(clothA).value();
  const std::vector<Vec3> start(positions.begin(), positions.end());
  ASSERT_TRUE(a.setState(clothA, start, velocities).ok());
  ASSERT_TRUE(b.setState(clothB, start, velocities).ok());
  for (int frame = 0; frame < 30; ++frame) {
    a.step(1.0 / 60);
    b.step(1.0 / 60);
    ASSERT_EQ(a.stateHash(), b.stateHash()) << "frame " << frame + 1;
    EXPECT_EQ(a.stats().bendingAssemblies, 0u);
    EXPECT_EQ(a.stats().dampingJacobians, 0u);
    EXPECT_GT(b.stats().bendingAssemblies, 0u);
    EXPECT_GT(b.stats().dampingJacobians, 0u);
  }
  // With bending and damping the terms are assembled either way.
  World c(skipping);
  ClothSettings damped = pinnedTopRow(columns, rows);
  damped.sleep.enabled = false;
  (void)c.createCloth(model, damped).value();
  c.step(1.0 / 60);
  EXPECT_GT(c.stats().bendingAssemblies, 0u);
  EXPECT_GT(c.stats().dampingJacobians, 0u);
}

TEST(Skip, SelfCollisionOffRunsNoSelfPass) {
  const Index columns = 9, rows = 7;
  World world;
  ClothSettings settings = pinnedTopRow(columns, rows);
  settings.selfCollision = false;
  (void)world.createCloth(grid(columns, rows, 0.4, 0.3), settings).value();
  world.step(1.0 / 60);
  EXPECT_EQ(world.stats().selfCollisionPasses, 0u);
  EXPECT_EQ(world.stats().selfCollisionSkipped, 0u);
}

// A strip folded in two on the floor: the lower layer lies on the floor with its far end (rows
// 0–9) held down by pins, the upper layer's free end is pinned, lifted and swung. Returns the
// world and its cloth. (Without the held end the whole lower layer is dragged about by the
// swinging upper one, a few mm per frame in some runs and at rest in others: the part that keeps
// still must be still by construction for the refit counts to mean something.)
struct FoldedStrip {
  std::unique_ptr<World> world;
  ClothId cloth;
  std::vector<Vec3> pinStart;  // the lifted row first, then the held rows
  Index liftedPins = 0;
};

FoldedStrip foldedStrip(bool skips) {
  constexpr Index kColumns = 11, kRows = 41;
  constexpr Real kSpacing = 0.025;
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  worldSettings.skipUnneededStages = skips;
  FoldedStrip strip;
  strip.world = std::make_unique<World>(worldSettings);
  (void)strip.world->addCollider(Plane::create(Vec3(0, 1, 0)).value()).value();
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  constexpr Index kHeldRows = 10;
  for (Index v = 0; v < kHeldRows * kColumns; ++v) settings.pinnedVertices.push_back(v);
  settings.sleep.enabled = false;
  auto model = grid(kColumns, kRows, (kColumns - 1) * kSpacing, (kRows - 1) * kSpacing);
  strip.cloth = strip.world->createCloth(model, settings).value();
  // Rows 0–20 lie on the floor along +z; rows 21–40 lie folded back over them, 1 cm higher.
  std::vector<Vec3> positions(model->vertexCount());
  for (Index r = 0; r < kRows; ++r) {
    for (Index c = 0; c < kColumns; ++c) {
      const bool lower = r <= kRows / 2;
      const Real z = lower ? r * kSpacing : (kRows - 1 - r) * kSpacing;
      positions[r * kColumns + c] = Vec3(c * kSpacing, lower ? 0.0035 : 0.0135, z);
    }
  }
  EXPECT_TRUE(strip.world->setState(strip.cloth, positions, std::vector<Vec3>(positions.size(),
                                                                           Vec3::Zero())).ok());
  for (Index vertex : settings.pinnedVertices) strip.pinStart.push_back(positions[vertex]);
  strip.liftedPins = kColumns;
  EXPECT_TRUE(strip.world->setPinTargets(strip.cloth, strip.pinStart).ok());
  return strip;
}

void stepStrip(FoldedStrip& strip, int frame) {
  // The pinned end rises to 25 cm over the first half second, then swings sideways.
  const Real t = (frame + 1) / 60.0;
  std::vector<Vec3> targets = strip.pinStart;
  for (Index pin = 0; pin < strip.liftedPins; ++pin) {
    targets[pin].y() += 0.25 * std::min<Real>(t / 0.5, 1);
    targets[pin].x() += 0.08 * std::sin(5 * t);
  }
  ASSERT_TRUE(strip.world->setPinTargets(strip.cloth, targets).ok());
  strip.world->step(1.0 / 60);
}

TEST(Skip, BvhRefitsOnlyTheMovingPartOfAFoldedStripWithTheSameBits) {
  FoldedStrip skipping = foldedStrip(true), full = foldedStrip(false);
  Index refit = 0, skipped = 0, fullRefit = 0;
  for (int frame = 0; frame < 60; ++frame) {
    stepStrip(skipping, frame);
    stepStrip(full, frame);
    ASSERT_EQ(skipping.world->stateHash(), full.world->stateHash()) << "frame " << frame + 1;
    const StepStats& s = skipping.world->stats();
    const StepStats& f = full.world->stats();
    EXPECT_EQ(f.bvhNodesSkipped, 0u);
    // The fold keeps the self-collision pass running (no culling) on both.
    EXPECT_EQ(s.selfCollisionPasses, f.selfCollisionPasses);
    if (frame >= 30) {
      refit += s.bvhNodesRefit;
      skipped += s.bvhNodesSkipped;
      fullRefit += f.bvhNodesRefit;
      EXPECT_EQ(s.bvhNodesRefit + s.bvhNodesSkipped, f.bvhNodesRefit);
    }
  }
  ASSERT_GT(fullRefit, 0u);
  std::printf("folded strip, frames 31-60: %llu BVH nodes refit, %llu kept (%.0f %%)\n",
              static_cast<unsigned long long>(refit), static_cast<unsigned long long>(skipped),
              100.0 * double(skipped) / double(refit + skipped));
  // The held quarter of the strip (rows 0–9) never moves: its leaves, and the nodes above only
  // them, are kept; the rest is dragged by the swinging layer and refit.
  EXPECT_GT(double(skipped), 0.15 * double(fullRefit));
  EXPECT_GT(double(refit), 0.3 * double(fullRefit));
}

TEST(FoldCulling, AFlatSheetCannotTouchItselfAFoldedOneCan) {
  const Index columns = 11, rows = 11;
  auto model = grid(columns, rows, 0.5, 0.5);  // spacing 5 cm
  FoldCulling culling(*model);
  ASSERT_TRUE(culling.applicable());
  const Vec3Array& rest = model->restPositions();
  const Real thickness = 0.003;
  EXPECT_TRUE(culling.cannotTouchItself(rest, rest, thickness));
  // A small motion keeps it clear, and so does any shift of the whole sheet (it moves no part
  // against another); half the sheet moving a spacing against the other may close a gap.
  Vec3Array moved = rest;
  for (Vec3& x : moved) x.z() += 0.004;
  EXPECT_TRUE(culling.cannotTouchItself(rest, moved, thickness));
  for (Vec3& x : moved) x += Vec3(1.0, -0.5, 0.3);
  EXPECT_TRUE(culling.cannotTouchItself(rest, moved, thickness));
  moved = rest;
  const Real middleColumn = rest[columns / 2].x();
  for (Vec3& x : moved) {
    if (x.x() > middleColumn) x.x() -= 0.06;
  }
  EXPECT_FALSE(culling.cannotTouchItself(rest, moved, thickness));
  // Folded in half: the upper half laid 2 mm above the lower one.
  Vec3Array folded = rest;
  const Real middle = rest[(rows / 2) * columns].y();
  for (Vec3& x : folded) {
    if (x.y() > middle) x = Vec3(x.x(), 2 * middle - x.y(), 0.002);
  }
  EXPECT_FALSE(culling.cannotTouchItself(folded, folded, thickness));
  // Bent gently over a cylinder of radius 1 m (half a radian): curved, but no fold.
  Vec3Array bent = rest;
  for (Vec3& x : bent) {
    const Real angle = x.y() - rest[0].y();
    x = Vec3(x.x(), rest[0].y() + std::sin(angle), 1 - std::cos(angle));
  }
  EXPECT_TRUE(culling.cannotTouchItself(bent, bent, thickness));
  // Rolled three quarters of the way round a cylinder, the sheet overlaps itself in any one
  // projection (half a roll would still be clear: seen from above, an arch is a rectangle).
  Vec3Array rolled = rest;
  const Real radius = 0.5 / (1.5 * 3.14159265358979);
  for (Vec3& x : rolled) {
    const Real angle = (x.y() - rest[0].y()) / radius;
    x = Vec3(x.x(), rest[0].y() + radius * std::sin(angle), radius * (1 - std::cos(angle)));
  }
  EXPECT_FALSE(culling.cannotTouchItself(rolled, rolled, thickness));
}

TEST(FoldCulling, ModelsThatAreNotOneDiskAreNotCulled) {
  // Two separate triangles.
  Vec3Array positions{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0),
                      Vec3(0, 0, 0.001), Vec3(1, 0, 0.001), Vec3(0, 1, 0.001)};
  std::vector<Index> indices{0, 1, 2, 3, 4, 5};
  Result<ClothModel> model = ClothModel::fromMesh(TriangleMesh{positions, indices, {}});
  ASSERT_TRUE(model.ok()) << model.error().message;
  FoldCulling culling(model.value());
  EXPECT_FALSE(culling.applicable());
  EXPECT_FALSE(culling.cannotTouchItself(positions, positions, 0.003));
}

}  // namespace
}  // namespace weft
