// Tests of the self-contact terms of the implicit solve (solver/ContactCoupling.h): the penalty
// kernel against finite differences, the matrix-free product against the dense JᵀJ, and
// FilteredPcg with couplings against a dense solve of (A + E) Δv = b, constrained and not, with
// the same bits on one and two threads.
#include <solver/BlockSparseMatrix.h>
#include <solver/ContactCoupling.h>
#include <solver/FilteredPcg.h>
#include <solver/VertexFilter.h>

#include <weft/threading/TaskSystem.h>

#include "RandomVectors.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <array>
#include <random>
#include <vector>

namespace weft {
namespace {

using Pair = std::array<Index, 2>;

using test::randomVec3;

Eigen::VectorXd flatten(const Vec3Array& x) {
  Eigen::VectorXd flat(3 * x.size());
  for (std::size_t i = 0; i < x.size(); ++i) flat.segment<3>(3 * Eigen::Index(i)) = x[i];
  return flat;
}

// A vertex–triangle pair (w = 1, −b) and an edge–edge pair (w = 1 − s, s, −(1 − u), −u).
std::array<Real, 4> vertexTriangleWeights() { return {1, -0.2, -0.5, -0.3}; }
std::array<Real, 4> edgeEdgeWeights() { return {0.7, 0.3, -0.4, -0.6}; }

// The dense 12-vector J = (w_0 n, …, w_3 n).
Eigen::Matrix<Real, 12, 1> denseJ(const std::array<Real, 4>& weights, const Vec3& normal) {
  Eigen::Matrix<Real, 12, 1> j;
  for (int k = 0; k < 4; ++k) j.segment<3>(3 * k) = weights[k] * normal;
  return j;
}

TEST(ContactPenalty, ForceIsMinusTheEnergyGradientAndItsJacobianIsMinusKJtJ) {
  std::mt19937 random(1);
  constexpr Real kThickness = 0.003, kStiffness = 260;
  for (const std::array<Real, 4>& weights : {vertexTriangleWeights(), edgeEdgeWeights()}) {
    const Vec3 normal = randomVec3(random).normalized();
    // Positions whose gap is 1 mm: inside the 3 mm thickness.
    std::array<Vec3, 4> x;
    for (Vec3& p : x) p = 0.01 * randomVec3(random);
    Vec3 point = Vec3::Zero();
    for (int k = 0; k < 4; ++k) point += weights[k] * x[k];
    x[0] += (0.001 - normal.dot(point)) / weights[0] * normal;
    const ContactPenalty penalty = contactPenalty(x, weights, normal, kThickness, kStiffness);
    ASSERT_TRUE(penalty.active);
    EXPECT_NEAR(penalty.gap, 0.001, 1e-15);
    EXPECT_NEAR(penalty.energy, 0.5 * kStiffness * 0.002 * 0.002, 1e-15);

    // Force λ w_k n against central differences of the energy.
    constexpr Real kStep = 1e-7;
    Eigen::Matrix<Real, 12, 1> force, gradient;
    for (int k = 0; k < 4; ++k) force.segment<3>(3 * k) = penalty.force * weights[k] * normal;
    for (int entry = 0; entry < 12; ++entry) {
      std::array<Vec3, 4> plus = x, minus = x;
      plus[entry / 3][entry % 3] += kStep;
      minus[entry / 3][entry % 3] -= kStep;
      gradient[entry] = (contactPenalty(plus, weights, normal, kThickness, kStiffness).energy -
                         contactPenalty(minus, weights, normal, kThickness, kStiffness).energy) /
                        (2 * kStep);
    }
    EXPECT_LE((force + gradient).norm(), 1e-6 * force.norm());

    // ∂f/∂x by differences of the force, against −k JᵀJ.
    Eigen::Matrix<Real, 12, 12> jacobian;
    for (int entry = 0; entry < 12; ++entry) {
      std::array<Vec3, 4> plus = x, minus = x;
      plus[entry / 3][entry % 3] += kStep;
      minus[entry / 3][entry % 3] -= kStep;
      const Real forcePlus = contactPenalty(plus, weights, normal, kThickness, kStiffness).force;
      const Real forceMinus = contactPenalty(minus, weights, normal, kThickness, kStiffness).force;
      jacobian.col(entry) = (forcePlus - forceMinus) / (2 * kStep) * denseJ(weights, normal);
    }
    const Eigen::Matrix<Real, 12, 1> j = denseJ(weights, normal);
    const Eigen::Matrix<Real, 12, 12> expected = -kStiffness * j * j.transpose();
    EXPECT_LE((jacobian - expected).norm(), 1e-6 * expected.norm());

    // Apart (gap 11 mm, beyond the thickness): no energy; the force extended linearly pulls.
    std::array<Vec3, 4> apart = x;
    apart[0] += 0.01 / weights[0] * normal;
    const ContactPenalty off = contactPenalty(apart, weights, normal, kThickness, kStiffness);
    EXPECT_FALSE(off.active);
    EXPECT_EQ(off.energy, 0);
    EXPECT_NEAR(off.force, kStiffness * (kThickness - 0.011), 1e-12);
  }
}

TEST(ContactCoupling, ProductEqualsTheDenseRankOneTermsAndSplitsIntoDiagonalAndCoupling) {
  std::mt19937 random(2);
  constexpr Index kRows = 10;
  std::vector<ContactCoupling> terms(2);
  terms[0] = {{0, 3, 4, 7}, vertexTriangleWeights(), randomVec3(random).normalized(), 2.5};
  terms[1] = {{3, kInvalidIndex, 9, 1}, edgeEdgeWeights(), randomVec3(random).normalized(), 0.7};
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * kRows, 3 * kRows);
  Eigen::MatrixXd diagonal = Eigen::MatrixXd::Zero(3 * kRows, 3 * kRows);
  for (const ContactCoupling& term : terms) {
    for (int i = 0; i < 4; ++i) {
      if (term.rows[i] == kInvalidIndex) continue;
      diagonal.block<3, 3>(3 * term.rows[i], 3 * term.rows[i]) += couplingDiagonalBlock(term, i);
      for (int k = 0; k < 4; ++k) {
        if (term.rows[k] == kInvalidIndex) continue;
        dense.block<3, 3>(3 * term.rows[i], 3 * term.rows[k]) +=
            term.coefficient * term.weights[i] * term.weights[k] * term.normal * term.normal.transpose();
      }
    }
  }
  Vec3Array x(kRows);
  for (Vec3& p : x) p = randomVec3(random);
  Vec3Array all(kRows, Vec3::Zero()), coupling(kRows, Vec3::Zero());
  addCouplingProduct(terms, x, all);
  addCouplingProduct(terms, x, coupling, /*offDiagonalOnly=*/true);
  EXPECT_LE((flatten(all) - dense * flatten(x)).norm(), 1e-14 * (dense * flatten(x)).norm());
  EXPECT_LE((flatten(coupling) - (dense - diagonal) * flatten(x)).norm(), 1e-14 * flatten(all).norm());
  // Positive semidefinite: xᵀ E x = Σ coefficient (J x)² ≥ 0.
  EXPECT_GE(flatten(x).dot(flatten(all)), 0);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues().minCoeff(), -1e-12);
}

// A grid cloth's system M + Σ spring stiffness (the engine's pattern), with stiff rank-one
// couplings between vertices the pattern does not join, as self-contacts of two layers are.
struct CoupledSystem {
  BlockSparseMatrix A;
  Vec3Array b;
  std::vector<ContactCoupling> couplings;
};

CoupledSystem makeCoupledSystem(Index vertexCount, unsigned seed) {
  std::mt19937 random(seed);
  constexpr Index kWidth = 20;
  std::vector<Pair> pairs;
  for (Index v = 0; v + kWidth + 1 < vertexCount; ++v) {
    if (v % kWidth == kWidth - 1) continue;
    for (const Pair& pair : {Pair{v, v + 1}, Pair{v, v + kWidth}, Pair{v, v + kWidth + 1}}) {
      pairs.push_back(pair);
    }
  }
  CoupledSystem system;
  system.A.build(vertexCount, pairs);
  std::uniform_real_distribution<Real> mass(0.5, 1.5);
  for (Index i = 0; i < vertexCount; ++i) {
    system.A.block(system.A.diagonalSlot(i)) += mass(random) * Mat3::Identity();
  }
  for (const Pair& pair : pairs) {
    const Vec3 axis = randomVec3(random);
    const Mat3 spring = 100 * (axis * axis.transpose() + 0.1 * Mat3::Identity());
    system.A.block(system.A.slot(pair[0], pair[0])) += spring;
    system.A.block(system.A.slot(pair[1], pair[1])) += spring;
    system.A.block(system.A.slot(pair[0], pair[1])) -= spring;
    system.A.block(system.A.slot(pair[1], pair[0])) -= spring;
  }
  // Couplings between the first and last thirds (the "layers"), as strong as the springs.
  std::uniform_int_distribution<Index> first(0, vertexCount / 3), last(2 * vertexCount / 3, vertexCount - 2);
  std::uniform_real_distribution<Real> barycentric(0.05, 0.95);
  for (Index k = 0; k < vertexCount / 10; ++k) {
    const Index p = first(random), q = last(random);
    const Real s = barycentric(random), u = barycentric(random);
    ContactCoupling term;
    if (k % 2 == 0) {
      term.rows = {p, q, q + 1, q + kWidth < vertexCount ? q + kWidth : q - kWidth};
      const Real c = 1 - s * u;
      term.weights = {1, -(1 - s) * c, -s * c, -(1 - c)};
    } else {
      term.rows = {p, p + 1, q, q + 1};
      term.weights = {1 - s, s, -(1 - u), -u};
    }
    term.normal = randomVec3(random).normalized();
    term.coefficient = 200 * barycentric(random);
    system.couplings.push_back(term);
  }
  system.b.resize(vertexCount);
  for (Vec3& v : system.b) v = randomVec3(random);
  return system;
}

Eigen::MatrixXd denseMatrix(const CoupledSystem& system) {
  Eigen::MatrixXd dense = Eigen::MatrixXd(system.A.toEigen());
  for (const ContactCoupling& term : system.couplings) {
    for (int i = 0; i < 4; ++i) {
      for (int k = 0; k < 4; ++k) {
        if (term.rows[i] == kInvalidIndex || term.rows[k] == kInvalidIndex) continue;
        dense.block<3, 3>(3 * term.rows[i], 3 * term.rows[k]) +=
            term.coefficient * term.weights[i] * term.weights[k] * term.normal * term.normal.transpose();
      }
    }
  }
  return dense;
}

class ContactCouplingPcgTest : public ::testing::TestWithParam<PreconditionerKind> {};

TEST_P(ContactCouplingPcgTest, SolvesTheCoupledSystemAsADenseSolveDoes) {
  constexpr Index kVertices = 300;
  const CoupledSystem system = makeCoupledSystem(kVertices, 3);
  ASSERT_FALSE(system.couplings.empty());
  const Eigen::MatrixXd dense = denseMatrix(system);
  const Eigen::VectorXd expected = dense.ldlt().solve(flatten(system.b));

  VertexFilter filter;
  filter.resize(kVertices);
  FilteredPcg pcg;
  PcgSettings settings;
  settings.preconditioner = GetParam();
  settings.tolerance = 1e-11;
  settings.maxIterations = 3000;
  settings.warmStart = false;
  Vec3Array deltaV;
  const SolveReport report =
      pcg.solve(system.A, system.b, filter, settings, deltaV, nullptr, {}, system.couplings);
  ASSERT_TRUE(report.converged);
  EXPECT_LE((flatten(deltaV) - expected).norm(), 1e-8 * expected.norm());

  // Without the couplings the answer is far from it: the test sees them.
  Vec3Array uncoupled;
  ASSERT_TRUE(pcg.solve(system.A, system.b, filter, settings, uncoupled).converged);
  EXPECT_GT((flatten(uncoupled) - expected).norm(), 1e-2 * expected.norm());
}

TEST_P(ContactCouplingPcgTest, ConstrainedRowsStayOnTargetAndTheFreePartMatchesTheReducedSystem) {
  constexpr Index kVertices = 300;
  const CoupledSystem system = makeCoupledSystem(kVertices, 4);
  // Constrain rows that couplings touch: one fixed (a pin kept in the system), one along a
  // normal (a collider contact), one in two directions.
  const ContactCoupling& term = system.couplings[0];
  const Index fixed = term.rows[0], oneDirection = term.rows[2], twoDirections = system.couplings[1].rows[1];
  ASSERT_NE(fixed, oneDirection);
  VertexFilter filter;
  filter.resize(kVertices);
  filter.setFixed(fixed, Vec3(0.3, -0.2, 0.1));
  const Vec3 normal = Vec3(0.2, 1, 0.1).normalized();
  filter.setConstrained(oneDirection, normal, Vec3(0.05 * normal));
  filter.setConstrained(twoDirections, Vec3::UnitX(), Vec3::UnitY(), Vec3(0.1, -0.1, 0));

  // Reduced dense solve: Δv = t + Q y, Qᵀ (A + E) Q y = Qᵀ (b − (A + E) t).
  Vec3Array target(kVertices);
  for (Index i = 0; i < kVertices; ++i) target[i] = filter.target(i);
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(3 * kVertices, 3 * kVertices);
  Eigen::Index columns = 0;
  for (Index i = 0; i < kVertices; ++i) {
    const Mat3 projection = filter.projection(i);  // S_i: onto the free subspace
    Eigen::SelfAdjointEigenSolver<Mat3> eigen(projection);
    for (int a = 0; a < 3; ++a) {
      if (eigen.eigenvalues()[a] > 0.5) basis.col(columns++).segment<3>(3 * i) = eigen.eigenvectors().col(a);
    }
  }
  basis.conservativeResize(Eigen::NoChange, columns);
  const Eigen::MatrixXd dense = denseMatrix(system);
  const Eigen::VectorXd t = flatten(target);
  const Eigen::VectorXd expected =
      t + basis * (basis.transpose() * dense * basis)
                      .ldlt()
                      .solve(basis.transpose() * (flatten(system.b) - dense * t));

  FilteredPcg pcg;
  PcgSettings settings;
  settings.preconditioner = GetParam();
  settings.tolerance = 1e-11;
  settings.maxIterations = 3000;
  settings.warmStart = false;
  Vec3Array deltaV;
  ASSERT_TRUE(pcg.solve(system.A, system.b, filter, settings, deltaV, nullptr, {}, system.couplings)
                  .converged);
  EXPECT_EQ(deltaV[fixed], filter.target(fixed));
  EXPECT_NEAR(deltaV[oneDirection].dot(normal), 0.05, 1e-14);
  EXPECT_LE((flatten(deltaV) - expected).norm(), 1e-8 * expected.norm());
}

TEST_P(ContactCouplingPcgTest, GivesTheSameBitsOnOneAndTwoThreads) {
  constexpr Index kVertices = 1200;  // several reduction blocks
  const CoupledSystem system = makeCoupledSystem(kVertices, 5);
  VertexFilter filter;
  filter.resize(kVertices);
  filter.setConstrained(system.couplings[2].rows[0], Vec3::UnitY(), Vec3(0, 0.01, 0));
  std::vector<Real> masses(kVertices, 1.0);
  PcgSettings settings;
  settings.preconditioner = GetParam();
  settings.stopping = PcgStopping::VelocityError;
  TaskSystem serial(TaskSystemSettings{1});
  TaskSystem twoThreads(TaskSystemSettings{2});
  Vec3Array results[3];
  SolveReport reports[3];
  TaskSystem* systems[3] = {nullptr, &serial, &twoThreads};
  for (int k = 0; k < 3; ++k) {
    FilteredPcg pcg;
    reports[k] = pcg.solve(system.A, system.b, filter, settings, results[k], systems[k], masses,
                           system.couplings);
    ASSERT_TRUE(reports[k].converged);
  }
  for (int k = 1; k < 3; ++k) {
    EXPECT_EQ(reports[k].iterations, reports[0].iterations);
    EXPECT_EQ(reports[k].relativeResidual, reports[0].relativeResidual);
    for (Index i = 0; i < kVertices; ++i) ASSERT_EQ(results[k][i], results[0][i]) << "vertex " << i;
  }
}

TEST_P(ContactCouplingPcgTest, ACouplingRowOutOfRangeIsRejected) {
  CoupledSystem system = makeCoupledSystem(100, 6);
  system.couplings[0].rows[1] = 100;
  VertexFilter filter;
  filter.resize(100);
  FilteredPcg pcg;
  PcgSettings settings;
  settings.preconditioner = GetParam();
  Vec3Array deltaV;
  const SolveReport report =
      pcg.solve(system.A, system.b, filter, settings, deltaV, nullptr, {}, system.couplings);
  EXPECT_FALSE(report.converged);
  EXPECT_TRUE(std::isnan(report.relativeResidual));
}

INSTANTIATE_TEST_SUITE_P(Preconditioners, ContactCouplingPcgTest,
                         ::testing::Values(PreconditionerKind::BlockJacobi,
                                           PreconditionerKind::MulticolorGaussSeidel,
                                           PreconditionerKind::TwoLevelGaussSeidel),
                         [](const ::testing::TestParamInfo<PreconditionerKind>& info) {
                           return info.param == PreconditionerKind::BlockJacobi ? "BlockJacobi"
                                  : info.param == PreconditionerKind::MulticolorGaussSeidel
                                      ? "GaussSeidel"
                                      : "TwoLevel";
                         });

}  // namespace
}  // namespace weft
