#include "ColliderProjection.h"
#include "StrainLimiting.h"

#include <weft/collision/Capsule.h>
#include <weft/collision/Shape.h>
#include <weft/collision/Sphere.h>
#include <weft/threading/TaskSystem.h>

#include <gtest/gtest.h>

#include <vector>

namespace weft {
namespace {

constexpr Real kThickness = 0.003;
constexpr Real kStep = 1.0 / 60;

// A collider at rest at `pose` (start and end of the step the same).
ColliderFrame still(Shape& shape) {
  ColliderFrame frame;
  frame.shape = &shape;
  frame.start = frame.end = motion(shape);
  return frame;
}

TEST(ColliderProjection, PutsAVertexInsideASphereOnItsThicknessAndMakesTheMoveAVelocity) {
  Shape sphere = Sphere::create(0.1).value();
  const std::vector<ColliderFrame> colliders{still(sphere)};
  const std::vector<Real> inverseMasses{1, 1};
  // Vertex 0 starts outside (within the margin) and is then pulled 1 cm into the sphere; vertex 1
  // is far away and not constrained.
  Vec3Array x{Vec3(0, 0.102, 0), Vec3(1, 0, 0)}, v(2, Vec3::Zero());
  ColliderProjection projection;
  projection.prepare(colliders, nullptr, {}, {}, inverseMasses, kThickness, 0.02, x);
  x[0] = Vec3(0, 0.09, 0);
  EXPECT_EQ(projection.project(x, v, 1 / kStep), 1);
  EXPECT_NEAR(x[0].y(), 0.1 + kThickness, 1e-12);
  EXPECT_NEAR(v[0].y(), (0.1 + kThickness - 0.09) / kStep, 1e-9);
  EXPECT_EQ(x[1], Vec3(1, 0, 0));
  // Satisfied now: nothing moves.
  EXPECT_EQ(projection.project(x, v, 1 / kStep), 0);
  EXPECT_NEAR(x[0].y(), 0.1 + kThickness, 1e-12);
}

TEST(ColliderProjection, AVertexPulledAcrossAThinCapsuleGoesBackToTheSideItCameFrom) {
  // A capsule of 1 cm radius along z; the vertex starts above it and is pulled to 3 mm below its
  // axis, still inside: the nearest surface is below, the side it came from above.
  RigidMotion pose;
  pose.pose.rotation = Quat::FromTwoVectors(Vec3::UnitY(), Vec3::UnitZ());
  Shape capsule = Capsule::create(0.01, 0.5, pose).value();
  const std::vector<ColliderFrame> colliders{still(capsule)};
  const std::vector<Real> inverseMasses{1};
  Vec3Array x{Vec3(0, 0.015, 0)}, v(1, Vec3::Zero());
  ColliderProjection projection;
  projection.prepare(colliders, nullptr, {}, {}, inverseMasses, kThickness, 0.02, x);
  x[0] = Vec3(0, -0.003, 0);
  (void)projection.project(x, v, 1 / kStep);
  EXPECT_GT(x[0].y(), 0.01 + kThickness - 1e-9) << "pushed out through the far side";
}

TEST(ColliderProjection, TheStrainLimiterSatisfiesItsEdgesAndTheCollidersTogether) {
  // An edge of rest length 0.1 m stretched to 0.2 m, its ends on a floor-like sphere's top, one
  // end pulled 5 mm into the sphere. The limiter alone shortens the edge along itself and leaves
  // the end inside; with the projection both hold at the end.
  Shape sphere = Sphere::create(1.0).value();
  const std::vector<ColliderFrame> colliders{still(sphere)};
  Edge edge;
  edge.vertices = {0, 1};
  edge.restLength = 0.1;
  const std::vector<Edge> edges{edge};
  const std::vector<Real> inverseMasses{1, 1};
  TaskSystem tasks(TaskSystemSettings{1});
  StrainLimiter limiter(edges, 2);
  StrainLimitSettings settings;
  settings.maxIterations = 256;
  const Vec3Array zeroNormals(2, Vec3::Zero());
  Vec3Array x{Vec3(-0.1, 1 + kThickness, 0), Vec3(0.1, 1 + kThickness, 0)}, v(2, Vec3::Zero());
  ColliderProjection projection;
  projection.prepare(colliders, nullptr, {}, {}, inverseMasses, kThickness, 0.05, x);
  x[1].y() -= 0.005;
  const StrainLimitReport report = limiter.applyInContact(settings, inverseMasses, zeroNormals,
                                                          kStep, x, v, tasks, {}, &projection);
  EXPECT_EQ(report.edgesOverLimit, 0);
  EXPECT_LE((x[1] - x[0]).norm(), (1 + settings.limit + settings.tolerance) * 0.1);
  for (const Vec3& point : x) {
    EXPECT_GT(point.norm(), 1 + kThickness - 0.01 * kThickness) << "a vertex left inside";
  }
}

}  // namespace
}  // namespace weft
