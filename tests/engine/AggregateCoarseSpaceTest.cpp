// Tests of AggregateCoarseSpace, the two-level preconditioner's coarse level: the aggregates, the
// correction against a dense Galerkin construction with pins and contact directions, thread
// independence, a non-finite system; and the two-level PCG's iterations under refinement.
// FilteredPcgTest and ContactCouplingPcgTest run the solver's contract tests for it too.
#include <solver/AggregateCoarseSpace.h>
#include <solver/BlockSparseMatrix.h>
#include <solver/FilteredPcg.h>
#include <solver/VertexFilter.h>

#include <weft/threading/TaskSystem.h>

#include "RandomVectors.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace weft {
namespace {

using Pair = std::array<Index, 2>;

using test::randomVec3;

/// A sheet of width × height vertices: unit masses, and on every edge of the triangulated grid
/// (right, down, one diagonal) a spring-like PSD stiffness `stiffness` · (a aᵀ + 0.1 I) coupling
/// its ends, a random axis a per edge. SPD; h²k/m grows like stiffness, so a finer sheet is a
/// stiffer one relative to its masses.
BlockSparseMatrix sheetSystem(Index width, Index height, Real stiffness, unsigned seed) {
  std::mt19937 random(seed);
  std::vector<Pair> pairs;
  for (Index y = 0; y < height; ++y) {
    for (Index x = 0; x < width; ++x) {
      const Index v = y * width + x;
      if (x + 1 < width) pairs.push_back({v, v + 1});
      if (y + 1 < height) pairs.push_back({v, v + width});
      if (x + 1 < width && y + 1 < height) pairs.push_back({v, v + width + 1});
    }
  }
  BlockSparseMatrix A(width * height, pairs);
  for (Index i = 0; i < width * height; ++i) A.block(A.diagonalSlot(i)) += Mat3::Identity();
  for (const auto& [i, j] : pairs) {
    const Vec3 axis = randomVec3(random).normalized();
    const Mat3 spring = stiffness * (axis * axis.transpose() + 0.1 * Mat3::Identity());
    A.block(A.slot(i, i)) += spring;
    A.block(A.slot(j, j)) += spring;
    A.block(A.slot(i, j)) -= spring;
    A.block(A.slot(j, i)) -= spring;
  }
  return A;
}

/// Every kind of constraint on some rows: fixed, one direction, two directions; the rest free.
VertexFilter mixedFilter(Index rows, unsigned seed) {
  std::mt19937 random(seed);
  VertexFilter filter;
  filter.resize(rows);
  for (Index i = 0; i < rows; ++i) {
    switch (i % 7) {
      case 1: filter.setFixed(i, randomVec3(random)); break;
      case 3: filter.setConstrained(i, randomVec3(random), randomVec3(random)); break;
      case 5:
        filter.setConstrained(i, randomVec3(random), randomVec3(random), randomVec3(random));
        break;
      default: break;
    }
  }
  // A block of rows all held along one normal: a translation the coarse basis loses.
  for (Index i = 0; i < std::min<Index>(rows, 40); ++i) {
    filter.setConstrained(i, Vec3(0, 0, 1), Vec3::Zero());
  }
  return filter;
}

Vec3Array filteredRandom(const VertexFilter& filter, std::mt19937& random) {
  Vec3Array r(filter.size());
  for (Index i = 0; i < filter.size(); ++i) r[i] = filter.filter(i, randomVec3(random));
  return r;
}

TEST(AggregateCoarseSpace, EveryRowJoinsOneAggregateWithAPatternNeighbour) {
  const BlockSparseMatrix A = sheetSystem(30, 20, 50, 1);
  AggregateCoarseSpace coarse;
  coarse.build(A);
  ASSERT_TRUE(coarse.built(A));
  const Index rows = A.blockRows(), count = coarse.aggregateCount();
  // A neighbourhood on this pattern holds up to 7 rows; pass 2 only enlarges aggregates.
  EXPECT_LE(count, rows / 3);
  EXPECT_GE(count, rows / 20);
  std::vector<Index> members(count, 0);
  for (Index row = 0; row < rows; ++row) {
    ASSERT_LT(coarse.aggregateOf()[row], count);
    ++members[coarse.aggregateOf()[row]];
  }
  for (Index aggregate = 0; aggregate < count; ++aggregate) EXPECT_GT(members[aggregate], 0u);
  // Connected: every row of an aggregate of several has a pattern neighbour in it.
  for (Index row = 0; row < rows; ++row) {
    const Index aggregate = coarse.aggregateOf()[row];
    if (members[aggregate] == 1) continue;
    bool neighbour = false;
    for (Index slot = A.rowBegin(row); slot < A.rowEnd(row); ++slot) {
      const Index column = A.column(slot);
      neighbour = neighbour || (column != row && coarse.aggregateOf()[column] == aggregate);
    }
    EXPECT_TRUE(neighbour) << "row " << row;
  }
  const BlockSparseMatrix other = sheetSystem(30, 20, 50, 1);
  EXPECT_FALSE(coarse.built(other));  // another pattern (a fresh build) is not this one
}

TEST(AggregateCoarseSpace, TheCorrectionIsTheGalerkinSolveOfTheFilteredSystem) {
  const BlockSparseMatrix A = sheetSystem(16, 12, 80, 2);
  const Index n = A.blockRows();
  const VertexFilter filter = mixedFilter(n, 3);
  AggregateCoarseSpace coarse;
  coarse.build(A);
  ASSERT_TRUE(coarse.assemble(A, filter, nullptr));
  const Index m = coarse.aggregateCount();

  // Dense: S, P₀, A_c = P₀ᵀ S A S P₀ and its pseudo-inverse (the translations S P₀ loses are its
  // null space, which P₀ᵀ S r never reaches).
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(3 * n, 3 * n), P = Eigen::MatrixXd::Zero(3 * n, 3 * m);
  for (Index i = 0; i < n; ++i) {
    S.block<3, 3>(3 * i, 3 * i) = filter.projection(i);
    P.block<3, 3>(3 * i, 3 * coarse.aggregateOf()[i]) = Mat3::Identity();
  }
  const Eigen::MatrixXd dense = Eigen::MatrixXd(A.toEigen());
  const Eigen::MatrixXd coarseMatrix = P.transpose() * S * dense * S * P;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(coarseMatrix);
  const Eigen::VectorXd values = eigen.eigenvalues();
  Eigen::VectorXd inverted = Eigen::VectorXd::Zero(values.size());
  for (Index k = 0; k < Index(values.size()); ++k) {
    if (values[k] > 1e-9 * values.maxCoeff()) inverted[k] = 1 / values[k];
  }
  const Eigen::MatrixXd pseudoInverse =
      eigen.eigenvectors() * inverted.asDiagonal() * eigen.eigenvectors().transpose();
  EXPECT_GT((values.array() <= 1e-9 * values.maxCoeff()).count(), 0)
      << "the filter should make the coarse basis lose a translation";

  std::mt19937 random(4);
  for (int trial = 0; trial < 3; ++trial) {
    const Vec3Array r = filteredRandom(filter, random);
    Vec3Array z(n, Vec3::Zero());
    const Real sum = coarse.addCorrection(filter, r, z, nullptr);
    Eigen::VectorXd flat(3 * n), got(3 * n);
    for (Index i = 0; i < n; ++i) {
      flat.segment<3>(3 * i) = r[i];
      got.segment<3>(3 * i) = z[i];
    }
    const Eigen::VectorXd expected = S * P * pseudoInverse * P.transpose() * S * flat;
    EXPECT_LE((got - expected).norm(), 1e-7 * expected.norm()) << "trial " << trial;
    EXPECT_NEAR(sum, flat.dot(got), 1e-12 * std::abs(sum) + 1e-300);  // z started at zero
    for (Index i = 0; i < n; ++i) {
      if (filter.kind(i) == ConstraintKind::Fixed) {
        EXPECT_EQ(z[i], Vec3::Zero()) << "row " << i;
      }
    }
  }
}

TEST(AggregateCoarseSpace, SameBitsOnAnyThreadCount) {
  const BlockSparseMatrix A = sheetSystem(60, 40, 200, 5);
  const Index n = A.blockRows();
  const VertexFilter filter = mixedFilter(n, 6);
  std::mt19937 random(7);
  const Vec3Array r = filteredRandom(filter, random);
  TaskSystem twoThreads(TaskSystemSettings{2});
  AggregateCoarseSpace serial, parallel;
  serial.build(A);
  parallel.build(A);
  ASSERT_TRUE(serial.assemble(A, filter, nullptr));
  ASSERT_TRUE(parallel.assemble(A, filter, &twoThreads));
  Vec3Array z1(n, Vec3::Ones()), z2(n, Vec3::Ones());
  const Real sum1 = serial.addCorrection(filter, r, z1, nullptr);
  const Real sum2 = parallel.addCorrection(filter, r, z2, &twoThreads);
  EXPECT_EQ(sum1, sum2);
  for (Index i = 0; i < n; ++i) ASSERT_EQ(z1[i], z2[i]) << "row " << i;
}

TEST(AggregateCoarseSpace, ANonFiniteSystemIsNotFactorisedAndAddsNothing) {
  BlockSparseMatrix A = sheetSystem(10, 10, 10, 8);
  A.block(A.slot(3, 4))(1, 2) = std::numeric_limits<Real>::quiet_NaN();
  VertexFilter filter;
  filter.resize(A.blockRows());
  AggregateCoarseSpace coarse;
  coarse.build(A);
  EXPECT_FALSE(coarse.assemble(A, filter, nullptr));
  EXPECT_FALSE(coarse.factorised());
  std::mt19937 random(9);
  const Vec3Array r = filteredRandom(filter, random);
  Vec3Array z(A.blockRows(), Vec3::Ones());
  EXPECT_EQ(coarse.addCorrection(filter, r, z, nullptr), 0);
  for (const Vec3& value : z) EXPECT_EQ(value, Vec3::Ones());
}

// The point of the coarse level: refining the sheet (4× the vertices, the same stiffness per
// edge, so 4× the stiffness relative to the masses, as on a finer cloth) multiplies Gauss–Seidel's
// iterations, while a two-level method's stay bounded independently of the refinement
// (aggregates of a fixed number of vertices, coarse problem solved exactly).
TEST(TwoLevelPcg, IterationsDoNotGrowWithRefinementAsGaussSeidelsDo) {
  auto iterations = [](Index width, Index height, Real stiffness, PreconditionerKind kind) {
    const BlockSparseMatrix A = sheetSystem(width, height, stiffness, 10);
    VertexFilter filter;
    filter.resize(A.blockRows());
    for (Index x = 0; x < width; ++x) filter.setFixed(x, Vec3::Zero());  // a pinned edge
    Vec3Array b(A.blockRows(), Vec3(0, 0, -1));  // gravity-like load
    PcgSettings settings;
    settings.preconditioner = kind;
    settings.stopping = PcgStopping::RelativeResidual;
    settings.tolerance = 1e-6;
    settings.maxIterations = 2000;
    settings.warmStart = false;
    FilteredPcg pcg;
    Vec3Array deltaV;
    const SolveReport report = pcg.solve(A, b, filter, settings, deltaV);
    EXPECT_TRUE(report.converged);
    return report.iterations;
  };
  const int gaussSeidelCoarse = iterations(20, 20, 100, PreconditionerKind::MulticolorGaussSeidel);
  const int gaussSeidelFine = iterations(40, 40, 400, PreconditionerKind::MulticolorGaussSeidel);
  const int twoLevelCoarse = iterations(20, 20, 100, PreconditionerKind::TwoLevelGaussSeidel);
  const int twoLevelFine = iterations(40, 40, 400, PreconditionerKind::TwoLevelGaussSeidel);
  std::printf("[two-level] Gauss-Seidel %d -> %d, two-level %d -> %d iterations\n",
              gaussSeidelCoarse, gaussSeidelFine, twoLevelCoarse, twoLevelFine);
  EXPECT_GE(gaussSeidelFine, 3 * gaussSeidelCoarse / 2);  // the growth the coarse level removes
  EXPECT_LE(twoLevelFine, twoLevelCoarse + twoLevelCoarse / 4);
  EXPECT_LT(twoLevelFine, gaussSeidelFine / 2);
}

}  // namespace
}  // namespace weft
