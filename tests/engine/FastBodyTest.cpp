// Bodies faster than a frame can see and bodies that close on the cloth: a 10 cm sphere at 5 to
// 250 m/s (up to 4.2 m a frame) through a 1 m sheet pinned on four, two or one of its edges, and
// two bodies closing to a gap below the cloth's thickness. The sphere must never pass through the
// sheet, and the squeezed cloth must end between the bodies, never inside one, the frame saying
// so. Where the engine does not yet hold that, the cases are marked as known engine failures.
#include "ContactTestSupport.h"
#include "KnownEngineFailure.h"

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

namespace weft {
namespace {

constexpr Real kFrame = 1.0 / 60.0;
constexpr Index kSide = 21;  // vertices along each side of the sheet
constexpr Real kSphereRadius = 0.1;  // m, of the fast sphere

enum class PinnedEdges { Four, TopAndBottom, Top };

std::string name(PinnedEdges edges) {
  switch (edges) {
    case PinnedEdges::Four: return "FourEdges";
    case PinnedEdges::TopAndBottom: return "TopAndBottom";
    case PinnedEdges::Top: return "Top";
  }
  return "";
}

class FastSphere : public ::testing::TestWithParam<std::tuple<Real, PinnedEdges>> {};

TEST_P(FastSphere, DoesNotPassThroughASheetPinnedOnItsEdges) {
  const auto [speed, edges] = GetParam();
  World world;
  const auto model = test::uprightSquare(kSide, 1.0, 0.5);
  ClothSettings settings;
  // Tunnelling, not strain: the kinematic sphere, which nothing stops, carries the sheet's middle
  // metres past its pins.
  settings.material.strainLimit = 0;
  for (Index k = 0; k < kSide; ++k) {
    settings.pinnedVertices.push_back((kSide - 1) * kSide + k);                      // top row
    if (edges != PinnedEdges::Top) settings.pinnedVertices.push_back(k);             // bottom row
    if (edges == PinnedEdges::Four && k > 0 && k + 1 < kSide) {
      settings.pinnedVertices.push_back(k * kSide);                                  // left column
      settings.pinnedVertices.push_back(k * kSide + kSide - 1);                      // right column
    }
  }
  const ClothId cloth = world.createCloth(model, settings).value();
  // Aimed at the sheet's middle, from 1 m in front of it.
  RigidMotion projectile;
  projectile.pose.position = Vec3(0, 1.0, -1.0);
  projectile.linearVelocity = Vec3(0, 0, speed);
  const ColliderId sphere =
      world.addCollider(Sphere::create(kSphereRadius, projectile).value()).value();
  test::IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  const Index middle = (kSide / 2) * kSide + kSide / 2;
  std::string broken;  // the frame the middle went through the sphere
  // The middle's distance from the line the sphere's centre travels (along z).
  const auto offAxis = [&](const Vec3& x) {
    return std::hypot(x.x() - projectile.pose.position.x(), x.y() - projectile.pose.position.y());
  };
  bool ahead = true;
  Real lastOffAxis = offAxis(world.positions(cloth).value()[middle]);
  // Until the sphere is 2 m past the sheet's plane.
  const int frames = int(std::ceil(3.0 / (speed * kFrame)));
  for (int frame = 0; frame < frames; ++frame) {
    health(world.step(kFrame));
    ASSERT_GE(test::closestApproach(world, cloth, sphere), 0.0) << "a vertex inside, frame " << frame;
    ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
    const Real sphereZ = motion(*world.collider(sphere).value()).pose.position.z();
    const Vec3& x = world.positions(cloth).value()[middle];
    // The middle may fall behind the sphere only by going round it (slipping off sideways or,
    // pinned at the top only, over the top), never through it: at the frame it first falls
    // behind, it and where it last was ahead lie outside the sphere's silhouette.
    if (ahead && !(x.z() > sphereZ)) {
      ahead = false;
      if (std::min(offAxis(x), lastOffAxis) < kSphereRadius && broken.empty()) {
        broken = "frame " + std::to_string(frame) + ": the middle went through the sphere (" +
                 std::to_string(std::min(offAxis(x), lastOffAxis)) + " m off its path)";
      }
    }
    lastOffAxis = offAxis(x);
  }
  EXPECT_EQ(health.rolledBack(), 0) << "fast sphere: a frame rolled back";
  EXPECT_TRUE(broken.empty()) << broken;
  // At 250 m/s the sphere crosses the sheet within a quarter of the frame, and the face contacts
  // carry the patch it crosses 3 m in the frame's one substep: an edge at the patch's rim passes
  // 100 times its rest length, and the health monitor redoes the frame with two substeps, which
  // carry the sheet ahead of the sphere (known failure: the retry; the outcome is asserted above).
  if (speed == 250) {
    test::knownEngineFailure(health.retried() == 0, "a sphere at 250 m/s needs no retried frame",
                             std::to_string(health.retried()) +
                                 " retried: one substep drags the patch the sphere crosses 3 m, "
                                 "past 100 times an edge's rest length");
    return;
  }
  health.expectHealthy("fast sphere");
}

TEST(FastSphere, AFrameRetriedWithMoreSubstepsEndsAsOneRunWithThemFromItsStart) {
  // The 250 m/s frame above, on the sheet hanging from its top: the health monitor redoes it
  // with two substeps. It must end bit for bit where the same frame run with two substeps does.
  auto run = [](Index substeps, StepStatus& status) {
    World world;
    ClothSettings settings;
    settings.material.strainLimit = 0;
    settings.solver.substeps = substeps;  // 0: automatic
    for (Index k = 0; k < kSide; ++k) settings.pinnedVertices.push_back((kSide - 1) * kSide + k);
    (void)world.createCloth(test::uprightSquare(kSide, 1.0, 0.5), settings).value();
    RigidMotion projectile;
    projectile.pose.position = Vec3(0, 1.0, -1.0);
    projectile.linearVelocity = Vec3(0, 0, 250);
    (void)world.addCollider(Sphere::create(kSphereRadius, projectile).value()).value();
    status = world.step(kFrame);
    return world.stateHash();
  };
  StepStatus retried, direct;
  const std::uint64_t afterRetry = run(0, retried);
  const std::uint64_t twoSubsteps = run(2, direct);
  ASSERT_TRUE(hasFlag(retried, StepStatus::RetriedWithSmallerStep))
      << describe(retried) << ": the frame is no longer retried; this test needs another that is";
  EXPECT_FALSE(hasFlag(direct, StepStatus::RetriedWithSmallerStep)) << describe(direct);
  EXPECT_EQ(afterRetry, twoSubsteps);
}

INSTANTIATE_TEST_SUITE_P(
    SpeedsAndPins, FastSphere,
    ::testing::Combine(::testing::Values(Real(5), Real(20), Real(30), Real(40), Real(50),
                                         Real(77), Real(100), Real(250)),
                       ::testing::Values(PinnedEdges::Four, PinnedEdges::TopAndBottom,
                                         PinnedEdges::Top)),
    [](const auto& info) {
      return std::to_string(int(std::get<0>(info.param))) + "MetresPerSecond" +
             name(std::get<1>(info.param));
    });

enum class Press { Box, MeshBox, Sphere, Capsule };

const char* name(Press press) {
  switch (press) {
    case Press::Box: return "Box";
    case Press::MeshBox: return "MeshBox";
    case Press::Sphere: return "Sphere";
    case Press::Capsule: return "Capsule";
  }
  return "";
}

// A box of half extents `half` as a closed triangle mesh (12 triangles, wound outwards).
TriangleMeshShape boxMesh(const Vec3& half, const RigidMotion& motion) {
  std::vector<Vec3> corners;
  for (int k = 0; k < 8; ++k) {
    corners.emplace_back((k & 1) ? half.x() : -half.x(), (k & 2) ? half.y() : -half.y(),
                         (k & 4) ? half.z() : -half.z());
  }
  const std::vector<Index> indices{0, 2, 1, 1, 2, 3,  4, 5, 6, 5, 7, 6,  0, 1, 4, 1, 5, 4,
                                   2, 6, 3, 3, 6, 7,  0, 4, 2, 2, 4, 6,  1, 3, 5, 3, 7, 5};
  return TriangleMeshShape::create(corners, indices, motion).value();
}

// The press and the gap (m) it stops at above the floor, below the cloth's 3 mm thickness.
class Squeeze : public ::testing::TestWithParam<std::tuple<Press, Real>> {};

TEST_P(Squeeze, ClothBetweenTwoBodiesClosingBelowItsThicknessEndsBetweenThem) {
  const auto [shape, gap] = GetParam();
  World world;
  // A 0.6 m sheet lying on a box whose top is at y = 0; a box (analytic, or a 12-triangle mesh),
  // a sphere or a capsule lying across comes down onto it at 0.5 m/s and stops `gap` above the
  // box. Under the box's edges the sheet steps from the gap up to its thickness, so the box's
  // edges, as face-contact cores, lie over the faces there.
  const Vec3 half(0.5, 0.1, 0.5);
  RigidMotion below;
  below.pose.position = Vec3(0, -half.y(), 0);
  const ColliderId floor = world.addCollider(Box::create(half, below).value()).value();
  const Vec3 pressHalf(0.15, 0.1, 0.15);  // the sphere's radius is pressHalf.y()
  RigidMotion press;
  press.pose.position = Vec3(0, 0.05 + pressHalf.y(), 0);
  press.linearVelocity = Vec3(0, -0.5, 0);
  ColliderId top;
  switch (shape) {
    case Press::Box: top = world.addCollider(Box::create(pressHalf, press).value()).value(); break;
    case Press::MeshBox: top = world.addCollider(boxMesh(pressHalf, press)).value(); break;
    case Press::Sphere:
      top = world.addCollider(Sphere::create(pressHalf.y(), press).value()).value();
      break;
    case Press::Capsule: {
      RigidMotion lying = press;  // its axis along x, a rod as long as the box is wide
      lying.pose.rotation = Quat(Eigen::AngleAxis<Real>(std::acos(Real(0)), Vec3::UnitZ()));
      top = world.addCollider(Capsule::create(pressHalf.y(), pressHalf.x(), lying).value()).value();
      break;
    }
  }
  // Cotton, with its strain limit: the press must neither tear the sheet out from between the
  // bodies nor stretch it past the limit.
  ClothSettings settings;
  settings.material = cottonFabric();
  const ClothId cloth =
      world.createCloth(test::horizontalSquare(kSide, 0.6, 0.003), settings).value();
  test::IntersectionCounter counter(world, {cloth});
  test::StepHealth health;
  bool closed = false, flagged = false;
  int unresolved = 0, overLimit = 0;  // frames with unresolved contacts, past the strain limit
  int firstUnresolved = -1;           // the first frame with unresolved contacts
  Real worstStrain = 0;
  std::string broken;  // the first frame with a vertex inside a body, and which
  auto check = [&](bool holds, int frame, const std::string& what) {
    if (!holds && broken.empty()) broken = "frame " + std::to_string(frame) + ": " + what;
  };
  for (int frame = 0; frame < 90; ++frame) {
    const Real bottom = motion(*world.collider(top).value()).pose.position.y() - pressHalf.y();
    if (!closed && bottom + press.linearVelocity.y() * kFrame <= gap) {
      // From where it is, stop at the gap at the end of this frame.
      press.pose = motion(*world.collider(top).value()).pose;
      press.linearVelocity = Vec3(0, (gap - bottom) / kFrame, 0);
      ASSERT_TRUE(world.setColliderMotion(top, press).ok());
      closed = true;
    } else if (closed && press.linearVelocity.y() != 0) {
      press.pose.position = Vec3(0, gap + pressHalf.y(), 0);
      press.linearVelocity = Vec3::Zero();
      ASSERT_TRUE(world.setColliderMotion(top, press).ok());
    }
    const StepStatus status = health(world.step(kFrame));
    // Flagged only with the press within twice the thickness of the floor; always under a box
    // (analytic or mesh), whose flat bottom holds the vertices it caught, and under the capsule,
    // whose length holds a row of them, while the cloth is stepped (asleep, it has no contacts to
    // report). A vertex under the sphere may be pushed aside to where the room is wider, so there
    // only the frame that closes the gap is sure.
    const Real pressBottom =
        motion(*world.collider(top).value()).pose.position.y() - pressHalf.y();
    const bool squeezed = hasFlag(status, StepStatus::Squeezed);
    const bool asleep = world.stats().sleepingCloths > 0;
    if (pressBottom >= 0.006) {
      EXPECT_FALSE(squeezed) << "frame " << frame;
    }
    if (pressBottom < 0.006 && !asleep && (shape != Press::Sphere || !flagged)) {
      EXPECT_TRUE(squeezed) << "frame " << frame << ", the press " << pressBottom << " m up";
    }
    flagged = flagged || squeezed;
    unresolved += hasFlag(status, StepStatus::ContactsUnresolved);
    if (firstUnresolved < 0 && hasFlag(status, StepStatus::ContactsUnresolved)) {
      firstUnresolved = frame;
    }
    overLimit += hasFlag(status, StepStatus::StrainLimitExceeded);
    worstStrain = std::max(worstStrain, world.stats().maxStrain);
    EXPECT_EQ(world.stats().squeezedVertices > 0, squeezed) << "frame " << frame;
    check(test::closestApproach(world, cloth, floor) >= 0, frame, "inside the floor");
    check(test::closestApproach(world, cloth, top) >= 0, frame, "inside the press");
    ASSERT_EQ(counter.count(world), 0u) << "intersecting triangle pairs, frame " << frame;
  }
  ASSERT_TRUE(closed);
  // The middle vertex is held in the gap.
  const Vec3& middle = world.positions(cloth).value()[(kSide / 2) * kSide + kSide / 2];
  EXPECT_GE(middle.y(), 0.0);
  EXPECT_LE(middle.y(), gap);
  health.expectHealthy("squeeze");
  // Room for each vertex and face exists at every gap: the projection finds it, within the strain
  // limit, in every frame.
  const bool held = broken.empty() && unresolved == 0 && overLimit == 0;
  const std::string figures =
      (broken.empty() ? std::string("outside both bodies") : broken) + "; " +
      std::to_string(unresolved) + " frames with unresolved contacts" +
      (firstUnresolved >= 0 ? " (the first: frame " + std::to_string(firstUnresolved) + ")" : "") +
      ", " +
      std::to_string(overLimit) + " past the strain limit (largest " +
      std::to_string(worstStrain) + ")";
  std::printf("[squeeze] %s to %.1f mm: %s\n", name(shape), 1000 * gap, figures.c_str());
  if (shape == Press::MeshBox && gap < 0.001) {
    test::knownEngineFailure(
        held, "a sheet squeezed to 0.5 mm under a box modelled as a mesh rests, resolved",
        figures + ". There, faces round the mesh's bottom corners keep their full "
                  "reach (0.75 mm) from the corner under a 0.5 mm gap: they came to it from below "
                  "and outwards, at 110 degrees to the floor's normal, short of the 120 at which "
                  "a face is taken as squeezed, and end the projection's 256 sweeps 0.3-0.6 mm "
                  "short");
    return;
  }
  EXPECT_TRUE(held) << figures;
}

INSTANTIATE_TEST_SUITE_P(
    Presses, Squeeze,
    ::testing::Combine(::testing::Values(Press::Box, Press::MeshBox, Press::Sphere,
                                         Press::Capsule),
                       ::testing::Values(Real(0.0005), Real(0.001), Real(0.0015), Real(0.002),
                                         Real(0.0025))),
    [](const auto& info) {
      return std::string(name(std::get<0>(info.param))) + "To" +
             std::to_string(int(std::lround(10000 * std::get<1>(info.param)))) + "TenthsOfAMillimetre";
    });

}  // namespace
}  // namespace weft
