// The curtain without contact: it settles to the static strain, warm starting pays, and the PCG
// solves the curtain's own system like a direct solver.
#include <weft/collision/SelfIntersectionCounter.h>
#include <weft/scenes/Curtain.h>

#include "ClothForces.h"
#include "ContactTestSupport.h"
#include "solver/FilteredPcg.h"
#include "solver/VertexFilter.h"

#include <Eigen/SparseCholesky>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

namespace weft {
namespace {

CurtainScene makeCurtain(const CurtainSettings& settings = {}) {
  Result<CurtainScene> scene = CurtainScene::create(settings);
  EXPECT_TRUE(scene.ok()) << scene.error().message;
  return std::move(scene).value();
}

TEST(Curtain, SizesRefineTheGrid) {
  for (Index size : {1u, 4u, 16u, 64u}) {
    const std::array<Index, 2> grid = CurtainScene::gridSize(size);
    EXPECT_EQ(2 * (grid[0] - 1) * (grid[1] - 1), 2400u * size);
  }
  CurtainSettings bad;
  bad.size = 3;
  Result<CurtainScene> scene = CurtainScene::create(bad);
  ASSERT_FALSE(scene.ok());
  EXPECT_NE(scene.error().message.find("choose 1, 4, 16 or 64"), std::string::npos);
}

TEST(Curtain, PinScriptGathersToThirtyPercentAndReopens) {
  const Vec3 right(1, 2, 0), left(-1, 2, 0);
  EXPECT_TRUE(CurtainScene::pinTarget(right, 3.0).isApprox(right));
  EXPECT_NEAR(CurtainScene::pinTarget(right, 7.0).x(), -1 + 2 * 0.3, 1e-12);
  EXPECT_TRUE(CurtainScene::pinTarget(left, 7.0).isApprox(left));
  EXPECT_TRUE(CurtainScene::pinTarget(right, 10.0).isApprox(right));
  EXPECT_NEAR(CurtainScene::pinTarget(right, 5.0).x(), -1 + 2 * 0.65, 1e-12);  // halfway
}

TEST(Curtain, SettlesToTheStaticStrainOfItsOwnWeight) {
  CurtainSettings settings;
  settings.pinScript = false;
  settings.sphere = false;  // hanging still: nothing to touch
  CurtainScene scene = makeCurtain(settings);
  for (Index frame = 0; frame < 180; ++frame) {
    const StepStatus status = scene.stepFrame();
    ASSERT_EQ(status, StepStatus::Ok) << describe(status) << " at frame " << frame;
  }
  const World& world = scene.world();
  const std::span<const Vec3> x = world.positions(scene.cloth()).value();
  for (const Vec3& p : x) ASSERT_TRUE(p.allFinite());

  // Under the top row, the cloth carries the weight of everything below it: tension per width
  // ρ_A g H, strain ρ_A g H / k_weft (no Poisson coupling in Baraff–Witkin stretch).
  const ClothMaterial material;
  const Real expectedTopStrain = material.arealDensity * 9.81 * 1.5 / material.weftStretchStiffness;
  const Index columns = 41, top = 30, middle = 20;
  const Real topEdge = (x[top * columns + middle] - x[(top - 1) * columns + middle]).norm();
  EXPECT_NEAR(topEdge / 0.05 - 1, expectedTopStrain, 0.15 * expectedTopStrain);
  // Strain falls to zero at the free bottom edge.
  const Real bottomEdge = (x[1 * columns + middle] - x[middle]).norm();
  EXPECT_LT(std::abs(bottomEdge / 0.05 - 1), 0.2 * expectedTopStrain);
  // Nowhere much above the static value (the pinned corners concentrate a little).
  EXPECT_LT(world.stats().maxStrain, 2.0 * expectedTopStrain);
  EXPECT_LT(world.stats().kineticEnergy, 1e-4);
}

TEST(Curtain, WarmStartSavesIterations) {
  // The same 3.5 s of the script (settle, then the rod starts gathering) with and without warm
  // start; the solver tolerance is the same, so only the starting guess differs.
  Index iterations[2] = {0, 0};
  for (int warm = 0; warm < 2; ++warm) {
    CurtainSettings settings;
    settings.solver.warmStart = warm == 1;
    CurtainScene scene = makeCurtain(settings);
    for (Index frame = 0; frame < 270; ++frame) {
      ASSERT_FALSE(hasFlag(scene.stepFrame(), StepStatus::RolledBack));
      if (frame >= 180) iterations[warm] += scene.world().stats().cgIterations;
    }
  }
  EXPECT_LT(iterations[1], iterations[0]) << "warm " << iterations[1] << " cold " << iterations[0];
}

TEST(Curtain, PcgMatchesADirectSolveOfTheCurtainSystem) {
  // Take the curtain mid-motion, assemble its backward-Euler system, pin the top row with
  // arbitrary targets, and compare the PCG (tight tolerance) with a sparse Cholesky solve of the
  // same system reduced to the free vertices.
  CurtainScene scene = makeCurtain();
  for (Index frame = 0; frame < 30; ++frame) scene.stepFrame();
  const ClothModel& model = scene.model();
  const Vec3Array x(scene.world().positions(scene.cloth()).value().begin(),
                    scene.world().positions(scene.cloth()).value().end());
  const Vec3Array v(scene.world().velocities(scene.cloth()).value().begin(),
                    scene.world().velocities(scene.cloth()).value().end());
  const Index n = model.vertexCount();

  ClothForces forces(model, ClothForceSettings{}, model.vertexMasses(0.15));
  BlockSparseMatrix matrix;
  matrix.build(n, forces.coupledPairs());
  forces.bindMatrix(matrix);
  const Real h = 1.0 / 60.0;
  Vec3Array f, kv, b(n);
  forces.assemble(x, v, h, matrix, f, v, kv);
  for (Index i = 0; i < n; ++i) b[i] = h * (f[i] + h * kv[i]);

  VertexFilter filter;
  filter.resize(n);
  std::mt19937 random(7);
  std::uniform_real_distribution<Real> uniform(-0.1, 0.1);
  std::vector<bool> pinned(n, false);
  for (Index column = 0; column < 41; ++column) {
    const Index vertex = 30 * 41 + column;
    pinned[vertex] = true;
    filter.setFixed(vertex, Vec3(uniform(random), uniform(random), uniform(random)));
  }
  FilteredPcg pcg;
  pcg.resize(n);
  PcgSettings settings;
  settings.tolerance = 1e-11;
  settings.maxIterations = 2000;
  settings.warmStart = false;
  Vec3Array deltaV(n, Vec3::Zero());
  const SolveReport report = pcg.solve(matrix, b, filter, settings, deltaV);
  ASSERT_TRUE(report.converged) << report.iterations << " iterations, residual " << report.relativeResidual;

  // Reduced system A_ff Δv_f = b_f − A_fp z_p.
  const Eigen::SparseMatrix<Real> full = matrix.toEigen();
  std::vector<int> freeIndex(3 * n, -1);
  int freeCount = 0;
  for (Index i = 0; i < n; ++i)
    if (!pinned[i]) for (int c = 0; c < 3; ++c) freeIndex[3 * i + c] = freeCount++;
  Eigen::VectorXd rhs(freeCount), pinnedValues = Eigen::VectorXd::Zero(3 * n);
  for (Index i = 0; i < n; ++i)
    if (pinned[i]) pinnedValues.segment<3>(3 * i) = filter.target(i);
  const Eigen::VectorXd coupling = full * pinnedValues;
  std::vector<Eigen::Triplet<Real>> triplets;
  for (int column = 0; column < full.outerSize(); ++column) {
    for (Eigen::SparseMatrix<Real>::InnerIterator it(full, column); it; ++it) {
      const int row = freeIndex[it.row()], col = freeIndex[it.col()];
      if (row >= 0 && col >= 0) triplets.emplace_back(row, col, it.value());
    }
  }
  for (Index i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (freeIndex[3 * i + c] >= 0) rhs(freeIndex[3 * i + c]) = b[i](c) - coupling(3 * i + c);
  Eigen::SparseMatrix<Real> reduced(freeCount, freeCount);
  reduced.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Real>> direct(reduced);
  ASSERT_EQ(direct.info(), Eigen::Success);
  const Eigen::VectorXd exact = direct.solve(rhs);

  Real errorSquared = 0, normSquared = 0;
  for (Index i = 0; i < n; ++i) {
    if (pinned[i]) {
      EXPECT_EQ(deltaV[i], filter.target(i));  // pins are exact, bit for bit
      continue;
    }
    const Vec3 reference(exact(freeIndex[3 * i]), exact(freeIndex[3 * i + 1]), exact(freeIndex[3 * i + 2]));
    errorSquared += (deltaV[i] - reference).squaredNorm();
    normSquared += reference.squaredNorm();
  }
  EXPECT_LT(std::sqrt(errorSquared / normSquared), 1e-8);
}

}  // namespace
}  // namespace weft

namespace weft {
namespace {

TEST(CurtainContact, TheFullScriptNeverIntersectsItselfNorEntersTheSphere) {
  // All 600 frames: sphere push, gathering to 30 %, hold, re-opening. After every frame the exact
  // triangle–triangle test finds no intersecting pair and no vertex is inside the sphere.
  CurtainScene scene = makeCurtain();
  SelfIntersectionCounter counter =
      SelfIntersectionCounter::create(scene.model().indices(), scene.model().restPositions()).value();
  Index impactsSeen = 0;
  Real maxStrain = 0;
  test::StepHealth health;
  for (Index frame = 0; frame < CurtainScene::kFrames; ++frame) {
    health(scene.stepFrame());
    maxStrain = std::max(maxStrain, scene.world().stats().maxStrain);
    const std::span<const Vec3> x = scene.world().positions(scene.cloth()).value();
    ASSERT_EQ(counter.count(x), 0u) << "intersecting triangle pairs after frame " << frame + 1;
    const Shape* sphere = scene.world().collider(scene.sphere()).value();
    for (const Vec3& p : x) ASSERT_GE(queryPoint(*sphere, p).distance, 0.0) << "frame " << frame + 1;
    impactsSeen += scene.world().stats().selfContacts + scene.world().stats().selfImpacts;
  }
  // The gathering does bring the cloth into contact with itself: the guarantee was exercised.
  EXPECT_GT(impactsSeen, 0u);
  // Cotton: within its strain limit + 0.01 at the end of every frame, and no frame rolled back or
  // retried.
  std::printf("[curtain] full script: max strain %.4f\n", maxStrain);
  EXPECT_LE(maxStrain, CurtainSettings{}.material.strainLimit + 0.01);
  health.expectHealthy("curtain");
}

}  // namespace
}  // namespace weft
