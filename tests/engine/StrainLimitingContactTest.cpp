// Strain limiting together with contact (engine/src/StrainLimiting.h, Cloth::limitStrainInContact):
// the kernel's held vertices and Gauss–Seidel order alone, then in a World, where a collider's
// response and friction used to stretch the cloth after the limiter.
#include "StrainLimiting.h"
#include "StrainLimitingTestSupport.h"
#include "ContactTestSupport.h"

#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace weft {
namespace {

using test::kStep;
using test::makeEdge;

TEST(StrainLimitingInContact, AHeldVertexSlidesOnItsSurfaceAndTheEdgeComesToTheLimit) {
  TaskSystem tasks(TaskSystemSettings{1});
  const std::vector<Edge> edges{makeEdge(0, 1, 1.0)};
  StrainLimiter limiter(edges, 2);
  const std::vector<Real> inverseMasses{1.0, 1.0};
  // Vertex 0 rests on the floor y = 0 (held along +y); vertex 1 hangs above it, the edge at
  // strain 0.5 and leaning 37° from the floor, so a free correction would lift vertex 0.
  const Vec3Array normals{Vec3(0, 1, 0), Vec3::Zero()};
  Vec3Array x{Vec3(0, 0, 0), Vec3(1.2, 0.9, 0)};
  Vec3Array v{Vec3(0.5, 0, 0), Vec3(0, -1, 0)};
  const Vec3Array x0 = x, v0 = v;
  const StrainLimitReport report =
      limiter.applyInContact({.limit = 0.1}, inverseMasses, normals, kStep, x, v, tasks);

  EXPECT_EQ(report.edgesOverLimit, 0u);
  EXPECT_LE((x[1] - x[0]).norm(), 1.1 * (1 + 1e-3));
  EXPECT_GT((x[1] - x[0]).norm(), 1.0);  // brought to the limit, not beyond it
  // Vertex 0 slid along the floor toward vertex 1 and stayed on it, bit for bit.
  EXPECT_EQ(x[0].y(), 0.0);
  EXPECT_EQ(v[0].y(), 0.0);
  EXPECT_GT(x[0].x(), 0.0);
  // Positions and velocities changed together: Δv = Δx / h.
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(((v[i] - v0[i]) * kStep - (x[i] - x0[i])).norm(), 0, 1e-12);

  // The same edge with the free limiter lifts vertex 0 off the floor: the hold is what keeps it.
  Vec3Array xFree = x0, vFree = v0;
  limiter.apply({.limit = 0.1}, inverseMasses, kStep, xFree, vFree, tasks);
  EXPECT_GT(xFree[0].y(), 0.01);
}

TEST(StrainLimitingInContact, AnEdgeHeldAlongItselfAtBothEndsIsLeftToTheCollisions) {
  TaskSystem tasks(TaskSystemSettings{1});
  const std::vector<Edge> edges{makeEdge(0, 1, 1.0)};
  StrainLimiter limiter(edges, 2);
  // Both ends held along the edge's own direction: no sliding shortens it.
  const Vec3Array normals{Vec3(1, 0, 0), Vec3(1, 0, 0)};
  Vec3Array x{Vec3(0, 0, 0), Vec3(1.5, 0, 0)}, v(2, Vec3::Zero());
  const Vec3Array x0 = x;
  const StrainLimitReport report =
      limiter.applyInContact({.limit = 0.1}, std::vector<Real>{1.0, 1.0}, normals, kStep, x, v, tasks);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_EQ(report.edgesOverLimit, 0u);  // not correctable, so not counted
  EXPECT_EQ(x, x0);
}

// An edge that leans only 3° off its held end's normal: its linearised correction, excess /
// √(1 − (n·d)²) across the normal, would carry that end 2 m along the floor, 33 times past the
// point where the edge is shortest (StrainLimiting.h, "A held end's step"), and stretch the end's
// other edge with it. The step is cut at the shortest point: this edge cannot reach the limit by
// sliding, so it is left no longer than it was, and the other edge stays within the limit.
TEST(StrainLimitingInContact, AHeldStepStopsWhereTheEdgeIsShortestInsteadOfOvershooting) {
  TaskSystem tasks(TaskSystemSettings{1});
  const std::vector<Edge> edges{makeEdge(0, 1, 1.0), makeEdge(0, 2, 0.1)};
  StrainLimiter limiter(edges, 3);
  // Vertex 0 on the floor (held along +y), vertex 1 fixed above it and 6 cm aside (strain 0.2),
  // vertex 2 free on the floor beside vertex 0, its edge at rest.
  const std::vector<Real> inverseMasses{1.0, 0.0, 1.0};
  const Vec3Array normals{Vec3(0, 1, 0), Vec3::Zero(), Vec3(0, 1, 0)};
  for (StrainLimitOrder order : {StrainLimitOrder::GaussSeidel, StrainLimitOrder::Jacobi}) {
    Vec3Array x{Vec3(0, 0, 0), Vec3(0.06, 1.2, 0), Vec3(-0.1, 0, 0)};
    Vec3Array v(3, Vec3::Zero());
    const Real before = (x[1] - x[0]).norm();
    const StrainLimitReport report = limiter.applyInContact(
        {.limit = 0.1, .order = order}, inverseMasses, normals, kStep, x, v, tasks);
    const bool gaussSeidel = order == StrainLimitOrder::GaussSeidel;
    // Slid toward the point under vertex 1, not past it, and stayed on the floor.
    EXPECT_GE(x[0].x(), 0.0) << gaussSeidel;
    EXPECT_LE(x[0].x(), 0.06 + 1e-9) << gaussSeidel;
    EXPECT_EQ(x[0].y(), 0.0) << gaussSeidel;
    EXPECT_LE((x[1] - x[0]).norm(), before) << gaussSeidel;
    EXPECT_NEAR((x[1] - x[0]).norm(), 1.2, 1e-3) << gaussSeidel;  // about as short as sliding makes it
    EXPECT_LE((x[2] - x[0]).norm(), 0.1 * (1.1 + 1e-3)) << gaussSeidel;
    EXPECT_EQ(report.edgesOverLimit, 0u) << gaussSeidel;  // the first edge: not correctable
  }
}

// A chain of 40 vertices hanging from a pin, stretched to strain 1: Gauss–Seidel passes each
// correction on within its sweep, where Jacobi moves each vertex by an average of its edges'
// corrections from the same positions. (Both need thousands of iterations: a long pinned chain
// of equal masses is the limiter's slowest case.)
TEST(StrainLimitingInContact, GaussSeidelBringsAChainWithinTheLimitInFewerIterationsThanJacobi) {
  TaskSystem tasks(TaskSystemSettings{2});
  constexpr Index kCount = 40;
  std::vector<Edge> edges;
  Vec3Array x0, v0(kCount, Vec3::Zero());
  std::vector<Real> inverseMasses;
  for (Index i = 0; i < kCount; ++i) {
    x0.emplace_back(0.01 * std::sin(Real(i)), -0.2 * Real(i), 0);
    inverseMasses.push_back(i == 0 ? 0 : 1000);
    if (i > 0) edges.push_back(makeEdge(i - 1, i, 0.1));
  }
  StrainLimiter limiter(edges, kCount);
  auto run = [&](StrainLimitOrder order) {
    Vec3Array x = x0, v = v0;
    const StrainLimitReport report = limiter.apply(
        {.limit = 0.1, .maxIterations = 100000, .order = order}, inverseMasses, kStep, x, v, tasks);
    std::printf("[strain] %s: %d iterations\n",
                order == StrainLimitOrder::GaussSeidel ? "Gauss-Seidel" : "Jacobi", report.iterations);
    return report;
  };
  const StrainLimitReport gaussSeidel = run(StrainLimitOrder::GaussSeidel);
  const StrainLimitReport jacobi = run(StrainLimitOrder::Jacobi);
  EXPECT_EQ(gaussSeidel.edgesOverLimit, 0u);
  EXPECT_EQ(jacobi.edgesOverLimit, 0u);
  // Measured: 4,463 and 17,415 iterations (3.9 times fewer).
  EXPECT_LT(3 * gaussSeidel.iterations, jacobi.iterations);
}

// ---------------------------------------------------------------------------------------------
// In a World, cotton (strain limit 0.10). The pass condition of the stress suite: the largest
// strain at the end of every frame within the limit + 0.01.

constexpr Real kAllowed = 0.10 + 0.01;


struct SpinRun {
  Real maxStrain = 0;
  Real closest = std::numeric_limits<Real>::infinity();  // m, nearest vertex to the sphere
  std::vector<std::uint64_t> hashes;
};

// A sheet dropped on a sphere spinning at 3 rad/s, friction 0.4: friction drags it round and,
// in the collider response after the limiter, used to stretch it (measured here: 0.236 with the
// limiter before the collisions only, Jacobi, 32 iterations).
SpinRun dropOnSpinningSphere(int threads) {
  TaskSystem tasks(TaskSystemSettings{threads});
  WorldSettings worldSettings;
  worldSettings.taskSystem = &tasks;
  World world(worldSettings);
  RigidMotion spinning;
  spinning.angularVelocity = Vec3(0, 3.0, 0);
  ColliderSettings colliderSettings;
  colliderSettings.friction = 0.4;
  const ColliderId sphere =
      world.addCollider(Sphere::create(0.2, spinning).value(), colliderSettings).value();
  ClothSettings settings;
  settings.material = cottonFabric();
  settings.material.friction = 0.4;
  settings.selfCollision = false;  // the collider path alone, and a fast test
  const ClothId cloth = world.createCloth(test::horizontalSquare(15, 0.7, 0.25), settings).value();
  SpinRun run;
  test::StepHealth health;
  for (int frame = 0; frame < 90; ++frame) {
    health(world.step(kStep));
    run.maxStrain = std::max(run.maxStrain, world.stats().maxStrain);
    const Shape* shape = world.collider(sphere).value();
    for (const Vec3& x : world.positions(cloth).value()) {
      run.closest = std::min(run.closest, queryPoint(*shape, x).distance);
    }
    run.hashes.push_back(world.stateHash());
  }
  health.expectHealthy("spinning sphere");
  return run;
}

TEST(StrainLimitingInContactWorld, ClothOnASpinningSphereWithFrictionStaysWithinTheLimit) {
  const SpinRun serial = dropOnSpinningSphere(1);
  EXPECT_LE(serial.maxStrain, kAllowed);
  EXPECT_GE(serial.closest, 0.0) << "a vertex ended a frame inside the sphere";
  // Held vertices, extra collider passes and the serial Gauss–Seidel sweeps: the same bits on
  // two threads.
  const SpinRun parallel = dropOnSpinningSphere(2);
  EXPECT_EQ(parallel.hashes, serial.hashes);
}

// A sheet pinned along its top edge, one implicit step per 1/30 s frame, and a sphere driven
// 12 cm into it: the steps carry it into the sphere, and the response pushing it back out used
// to stretch it beyond the limit after the limiter (measured here: 0.254 with the limiter before
// the collisions only, Jacobi, 32 iterations).
TEST(StrainLimitingInContactWorld, ASpherePushedIntoAHangingSheetWithLargeStepsStaysWithinTheLimit) {
  constexpr Index kVertices = 21;
  constexpr Real kFrame = 1.0 / 30.0;
  GridSettings grid;
  grid.columns = grid.rows = kVertices;
  grid.width = grid.height = 1.0;
  grid.origin = Vec3(-0.5, 0.2, 0);
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  ClothSettings settings;
  settings.material = cottonFabric();
  settings.solver.substeps = 1;
  for (Index k = 0; k < kVertices; ++k) settings.pinnedVertices.push_back((kVertices - 1) * kVertices + k);
  World world;
  const ClothId cloth = world.createCloth(model, settings).value();
  RigidMotion pusher;
  pusher.pose.position = Vec3(0, 0.6, -0.3);
  pusher.linearVelocity = Vec3(0, 0, 0.6);  // 0.42 m in 0.7 s: its front ends 0.27 m past the sheet
  const ColliderId sphere = world.addCollider(Sphere::create(0.15, pusher).value()).value();
  Real maxStrain = 0;
  test::StepHealth health;
  for (int frame = 0; frame < 30; ++frame) {
    if (frame == 21) {
      RigidMotion still = motion(*world.collider(sphere).value());
      still.linearVelocity = Vec3::Zero();
      ASSERT_TRUE(world.setColliderMotion(sphere, still).ok());
    }
    health(world.step(kFrame));
    maxStrain = std::max(maxStrain, world.stats().maxStrain);
    const Shape* shape = world.collider(sphere).value();
    for (const Vec3& x : world.positions(cloth).value()) {
      ASSERT_GE(queryPoint(*shape, x).distance, 0.0) << "frame " << frame;
    }
  }
  // The sphere did push the sheet (its middle moved well beyond its plane).
  EXPECT_GT(world.positions(cloth).value()[10 * kVertices + 10].z(), 0.1);
  EXPECT_LE(maxStrain, kAllowed);
  health.expectHealthy("sphere into a hanging sheet");
}

}  // namespace
}  // namespace weft
