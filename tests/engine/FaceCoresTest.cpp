// facePoints, the kernel of the face–collider contacts (FaceCores.h), on single faces and cores:
// which side of a core a face is sent to, and how far.
#include "contact/FaceCores.h"

#include <gtest/gtest.h>

#include <array>

namespace weft {
namespace {

constexpr Real kReach = 0.0015;  // a box edge's reach at a 3 mm allowance

// A horizontal face at height `y` whose interior holds the line x = z = 0.
std::array<Vec3, 3> faceAround(Real y) {
  return {Vec3(-0.03, y, -0.03), Vec3(0.06, y, -0.03), Vec3(-0.03, y, 0.06)};
}

// The deepest point facePoints() reports (0 when none).
FacePoint deepest(const FaceCore& core, const Vec3& cameFrom, const std::array<Vec3, 3>& face) {
  std::array<FacePoint, 3> points;
  const int count = facePoints(core, cameFrom, face[0], face[1], face[2], 0, points);
  FacePoint best;
  for (int p = 0; p < count; ++p) {
    if (points[p].depth > best.depth) best = points[p];
  }
  return best;
}

TEST(FacePoints, AFaceThatCameFromBesideACoreIsNotPushedAlongIt) {
  // A box's vertical edge, 0.2 m long, through a horizontal face 1.5 mm above its lower end, the
  // face having started beside it: the start's normal lies in the face's plane, its component
  // along the face's normal a rounding's sign either way. That sign must not send the face past
  // the core's far end, 0.2 m along it.
  const FaceCore edge = makeCore(Vec3(0, -0.1, 0), Vec3(0, 0.1, 0), kReach);
  const std::array<Vec3, 3> face = faceAround(-0.0985);
  for (Real lean : {1e-12, -1e-12, 0.1, -0.1}) {
    const FacePoint point = deepest(edge, Vec3(-1, lean, 0).normalized(), face);
    EXPECT_LE(point.depth, kReach) << "start normal leaning " << lean << " out of the face's plane";
  }
}

TEST(FacePoints, AFaceThatCrossedACoreGoesBackToTheSideItCameFrom) {
  // The same edge lying along x, 1 mm above the face: a face that came from above it (the start's
  // normal along +y) goes back above, the edge's height plus its reach; one that came from below
  // stays below, its reach less the 1 mm.
  const FaceCore edge = makeCore(Vec3(-0.01, 0.001, 0.01), Vec3(0.02, 0.001, 0.01), kReach);
  const std::array<Vec3, 3> face = faceAround(0);
  const FacePoint fromAbove = deepest(edge, Vec3(0, 1, 0), face);
  EXPECT_NEAR(fromAbove.depth, kReach + 0.001, 1e-12);
  EXPECT_NEAR(fromAbove.normal.y(), 1, 1e-12);
  const FacePoint fromBelow = deepest(edge, Vec3(0, -1, 0), face);
  EXPECT_NEAR(fromBelow.depth, kReach - 0.001, 1e-12);
  EXPECT_NEAR(fromBelow.normal.y(), -1, 1e-12);
}

}  // namespace
}  // namespace weft
