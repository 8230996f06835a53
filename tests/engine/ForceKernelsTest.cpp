// Tests of the pure force kernels (forces/Condition.h, BaraffWitkin.h, SpringCondition.h), alone.
//
// Every derivative is checked against central finite differences of the quantity it differentiates
// (C, the energy, the force), on random non-trivially deformed elements at two scales (1 m and a
// cloth-sized 5 cm) and, for bending, on hand-made near-flat, strongly folded and near ±π hinges.
// The step is 1e-6 of the element size and errors are compared in norm, relative to the larger
// of the two matrices: central differences are accurate to ~1e-10 there, so 1e-6 catches any
// wrong term while never tripping on rounding.
#include <forces/BaraffWitkin.h>
#include <forces/Condition.h>
#include <forces/SpringCondition.h>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace weft {
namespace {

constexpr Real kPi = std::numbers::pi_v<Real>;
/// Finite-difference step as a fraction of the element size.
constexpr Real kRelativeStep = 1e-6;
/// Allowed norm-relative error between analytic and finite-difference derivatives.
constexpr Real kTolerance = 1e-6;

template <int N>
using Positions = Eigen::Matrix<Real, 3 * N, 1>;
template <int N>
using ConditionFunction = std::function<Condition<N>(const Positions<N>&, bool withHessian)>;

/// One element to test: a condition, where to evaluate it, and the length scale of the element.
template <int N>
struct Case {
  std::string name;
  ConditionFunction<N> condition;
  Positions<N> positions;
  Real size = 1;  ///< m, sets the finite-difference step
};

Real relativeError(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  const Real scale = std::max({actual.norm(), expected.norm(), Real(1e-300)});
  return (actual - expected).norm() / scale;
}

/// Central differences of a scalar function of the element positions.
template <int N>
Positions<N> finiteDifferenceGradient(const std::function<Real(const Positions<N>&)>& f,
                                      const Positions<N>& x, Real step) {
  Positions<N> gradient;
  for (int i = 0; i < 3 * N; ++i) {
    Positions<N> plus = x, minus = x;
    plus[i] += step;
    minus[i] -= step;
    gradient[i] = (f(plus) - f(minus)) / (2 * step);
  }
  return gradient;
}

/// Central differences of a vector function: column j is ∂f/∂x_j.
template <int N>
Eigen::Matrix<Real, 3 * N, 3 * N> finiteDifferenceJacobian(
    const std::function<Positions<N>(const Positions<N>&)>& f, const Positions<N>& x, Real step) {
  Eigen::Matrix<Real, 3 * N, 3 * N> jacobian;
  for (int j = 0; j < 3 * N; ++j) {
    Positions<N> plus = x, minus = x;
    plus[j] += step;
    minus[j] -= step;
    jacobian.col(j) = (f(plus) - f(minus)) / (2 * step);
  }
  return jacobian;
}

template <int N>
ElementForces<N> elementForces(const Condition<N>& condition, Real stiffness, Real damping,
                               const Positions<N>& velocities, StiffnessMode mode) {
  ElementForces<N> forces;
  accumulateConditionForces(condition, stiffness, damping, velocities, mode, true, forces);
  return forces;
}

// ---------------------------------------------------------------------------------------------
// Configurations

class Random {
 public:
  explicit Random(unsigned seed) : m_engine(seed) {}
  Real uniform(Real lo, Real hi) { return std::uniform_real_distribution<Real>(lo, hi)(m_engine); }
  Vec3 vector(Real amplitude) {
    return Vec3(uniform(-amplitude, amplitude), uniform(-amplitude, amplitude),
                uniform(-amplitude, amplitude));
  }
  Mat3 rotation() {
    Eigen::Quaternion<Real> q(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    q.normalize();
    return q.toRotationMatrix();
  }

 private:
  std::mt19937 m_engine;
};

/// A triangle with material coordinates and a deformed placement x_i = F uv_i + t + noise.
struct TriangleSetup {
  std::array<Vec2, 3> uv;
  TriangleRest rest;
  Positions<3> positions;
  Real size = 1;
};

std::array<Vec2, 3> randomMaterialTriangle(Random& random, Real size) {
  // Perturbed right triangle: far from degenerate, with no special alignment to u or v.
  const Vec2 uv0(random.uniform(-size, size), random.uniform(-size, size));
  const Vec2 uv1 = uv0 + size * Vec2(1 + random.uniform(-0.3, 0.3), random.uniform(-0.3, 0.3));
  const Vec2 uv2 = uv0 + size * Vec2(random.uniform(-0.3, 0.3), 1 + random.uniform(-0.3, 0.3));
  return {uv0, uv1, uv2};
}

/// Places the material triangle through the 3×2 deformation gradient `deformation`, then a
/// rotation, a translation and per-vertex noise of relative amplitude `noise`.
TriangleSetup placeTriangle(const std::array<Vec2, 3>& uv, const Eigen::Matrix<Real, 3, 2>& deformation,
                            const Mat3& rotation, const Vec3& translation, Random& random,
                            Real noise, Real size) {
  TriangleSetup setup;
  setup.uv = uv;
  setup.rest = makeTriangleRest({0, 1, 2}, uv[0], uv[1], uv[2]);
  for (int i = 0; i < 3; ++i) {
    setup.positions.segment<3>(3 * i) =
        rotation * (deformation * uv[i]) + translation + random.vector(noise * size);
  }
  setup.size = size;
  return setup;
}

Eigen::Matrix<Real, 3, 2> planarDeformation(Real a, Real b, Real c, Real d) {
  Eigen::Matrix<Real, 3, 2> deformation;
  deformation << a, b, c, d, 0, 0;
  return deformation;
}

TriangleSetup randomTriangle(Random& random, Real size) {
  Eigen::Matrix<Real, 3, 2> deformation = planarDeformation(1, 0, 0, 1);
  // Stretch, shear and bend the map out of plane by up to ~40 %.
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 2; ++j) {
      deformation(i, j) += random.uniform(-0.4, 0.4);
    }
  }
  return placeTriangle(randomMaterialTriangle(random, size), deformation, random.rotation(),
                       random.vector(2), random, 0.1, size);
}

/// A hinge with dihedral angle exactly `angle` (when noise = 0), rigidly moved, then perturbed.
Positions<4> hingePositions(Random& random, Real angle, Real size, Real noise) {
  // Edge along +x; A in the z = 0 plane above it (n_A = +z); B below, rotated about the edge so
  // that it turns towards +z (towards n_A) for positive angles.
  const Real reachA = random.uniform(0.5, 1.0);
  const Real reachB = random.uniform(0.5, 1.0);
  const std::array<Vec3, 4> local = {
      Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(random.uniform(0, 1), reachA, 0),
      Vec3(random.uniform(0, 1), -reachB * std::cos(angle), reachB * std::sin(angle))};
  const Mat3 rotation = random.rotation();
  const Vec3 translation = random.vector(2);
  Positions<4> positions;
  for (int i = 0; i < 4; ++i) {
    positions.segment<3>(3 * i) =
        rotation * (size * local[i]) + translation + random.vector(noise * size);
  }
  return positions;
}

Hinge hingeFor(const Positions<4>& positions, Real restAngle) {
  Hinge hinge;
  hinge.vertices = {0, 1, 2, 3};
  hinge.restAngle = restAngle;
  const Vec3 x0 = positions.segment<3>(0), x1 = positions.segment<3>(3);
  const Vec3 x2 = positions.segment<3>(6), x3 = positions.segment<3>(9);
  hinge.restLength = (x1 - x0).norm();
  const Real areaA = (x1 - x0).cross(x2 - x0).norm() / 2;
  const Real areaB = (x3 - x0).cross(x1 - x0).norm() / 2;
  hinge.stiffnessScale = hingeStiffnessScale(hinge.restLength, areaA, areaB);
  return hinge;
}

ConditionFunction<3> warpCondition(const TriangleRest& rest, Real warpScale, Real weftScale) {
  return [=](const Positions<3>& x, bool withHessian) {
    return stretchConditions(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), rest, warpScale,
                             weftScale, withHessian)
        .warp;
  };
}

ConditionFunction<3> weftCondition(const TriangleRest& rest, Real warpScale, Real weftScale) {
  return [=](const Positions<3>& x, bool withHessian) {
    return stretchConditions(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), rest, warpScale,
                             weftScale, withHessian)
        .weft;
  };
}

ConditionFunction<3> shearConditionOf(const TriangleRest& rest) {
  return [=](const Positions<3>& x, bool withHessian) {
    return shearCondition(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), rest, withHessian);
  };
}

ConditionFunction<4> bendConditionOf(const Hinge& hinge) {
  return [=](const Positions<4>& x, bool withHessian) {
    return bendCondition(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), x.segment<3>(9),
                         hinge, withHessian);
  };
}

ConditionFunction<2> springConditionOf(Real restLength) {
  return [=](const Positions<2>& x, bool withHessian) {
    return springCondition(x.segment<3>(0), x.segment<3>(3), restLength, withHessian);
  };
}

/// Stretch warp, stretch weft and shear on random deformed triangles at 1 m and 5 cm.
std::vector<Case<3>> triangleCases() {
  std::vector<Case<3>> cases;
  Random random(7);
  for (Real size : {1.0, 0.05}) {
    for (int trial = 0; trial < 4; ++trial) {
      const TriangleSetup setup = randomTriangle(random, size);
      const Real warpScale = random.uniform(0.9, 1.1);
      const Real weftScale = random.uniform(0.9, 1.1);
      const std::string suffix = " size " + std::to_string(size) + " #" + std::to_string(trial);
      cases.push_back({"warp" + suffix, warpCondition(setup.rest, warpScale, weftScale),
                       setup.positions, size});
      cases.push_back({"weft" + suffix, weftCondition(setup.rest, warpScale, weftScale),
                       setup.positions, size});
      cases.push_back({"shear" + suffix, shearConditionOf(setup.rest), setup.positions, size});
    }
  }
  return cases;
}

/// Bending on random, near-flat, strongly folded and near ±π hinges, with flat and curved rest.
std::vector<Case<4>> hingeCases() {
  std::vector<Case<4>> cases;
  Random random(11);
  auto add = [&](const std::string& name, Real angle, Real restAngle, Real size, Real noise) {
    const Positions<4> positions = hingePositions(random, angle, size, noise);
    // Rest data from a flat copy, so the stiffness scale is that of a real rest hinge.
    const Hinge hinge = hingeFor(hingePositions(random, 0, size, 0), restAngle);
    cases.push_back({name, bendConditionOf(hinge), positions, size});
  };
  for (Real size : {1.0, 0.05}) {
    for (int trial = 0; trial < 4; ++trial) {
      add("random #" + std::to_string(trial), random.uniform(-2.5, 2.5), 0, size, 0.1);
    }
    add("near flat", 1e-4, 0, size, 0);
    add("exactly flat, curved rest", 0, 0.6, size, 0);
    add("folded towards A", 2.7, 0, size, 0.02);
    add("folded away from A", -2.7, 0, size, 0.02);
    add("near +pi", kPi - 1e-3, 0, size, 0);
    add("near -pi", -kPi + 1e-3, 0, size, 0);
    add("near -pi, rest near +pi (wraps)", -kPi + 0.05, kPi - 0.1, size, 0);
    add("curved rest", 0.9, -0.4, size, 0.05);
  }
  return cases;
}

/// Springs stretched and compressed, at 1 m and 5 cm.
std::vector<Case<2>> springCases() {
  std::vector<Case<2>> cases;
  Random random(13);
  for (Real size : {1.0, 0.05}) {
    for (Real ratio : {0.5, 0.9, 1.2, 1.7}) {
      const Vec3 x0 = random.vector(2);
      const Vec3 direction = random.rotation() * Vec3::UnitX();
      Positions<2> positions;
      positions << x0, x0 + ratio * size * direction;
      cases.push_back({"length ratio " + std::to_string(ratio) + " size " + std::to_string(size),
                       springConditionOf(size), positions, size});
    }
  }
  return cases;
}

// ---------------------------------------------------------------------------------------------
// Generic checks, applied to every condition

/// ∇C and ∇²C against finite differences of C and ∇C; Hessian symmetry; ∇C with and without
/// Hessian agree; the elastic force is minus the finite-difference gradient of the energy.
template <int N>
void expectDerivativesMatchFiniteDifferences(const Case<N>& element) {
  SCOPED_TRACE(element.name);
  const Real step = kRelativeStep * element.size;
  const Condition<N> condition = element.condition(element.positions, true);
  ASSERT_TRUE(std::isfinite(condition.value));

  const auto value = [&](const Positions<N>& x) { return element.condition(x, false).value; };
  EXPECT_LE(relativeError(condition.gradient,
                          finiteDifferenceGradient<N>(value, element.positions, step)),
            kTolerance);

  const auto gradient = [&](const Positions<N>& x) -> Positions<N> {
    return element.condition(x, false).gradient;
  };
  EXPECT_LE(relativeError(condition.hessian,
                          finiteDifferenceJacobian<N>(gradient, element.positions, step)),
            kTolerance);

  EXPECT_LE((condition.hessian - condition.hessian.transpose()).norm(),
            1e-12 * condition.hessian.norm());
  EXPECT_EQ(element.condition(element.positions, false).gradient, condition.gradient);

  const Real stiffness = 3.7;
  const auto energy = [&](const Positions<N>& x) {
    const Real c = element.condition(x, false).value;
    return stiffness / 2 * c * c;
  };
  const ElementForces<N> forces = elementForces(condition, stiffness, 0, Positions<N>::Zero(),
                                                StiffnessMode::Exact);
  EXPECT_NEAR(forces.energy, energy(element.positions), 1e-15 * (1 + forces.energy));
  EXPECT_LE(relativeError(-forces.force,
                          finiteDifferenceGradient<N>(energy, element.positions, step)),
            kTolerance);
}

/// With damping on and v fixed: Exact ∂f/∂x and ∂f/∂v against finite differences of the force.
template <int N>
void expectForceJacobiansMatchFiniteDifferences(const Case<N>& element, Random& random) {
  SCOPED_TRACE(element.name);
  const Real step = kRelativeStep * element.size;
  const Real stiffness = 5.0, damping = 0.8;
  Positions<N> velocities;
  for (int i = 0; i < 3 * N; ++i) {
    velocities[i] = random.uniform(-1, 1);
  }
  const ElementForces<N> forces =
      elementForces(element.condition(element.positions, true), stiffness, damping, velocities,
                    StiffnessMode::Exact);

  const auto forceOfPositions = [&](const Positions<N>& x) -> Positions<N> {
    return elementForces(element.condition(x, true), stiffness, damping, velocities,
                         StiffnessMode::Exact)
        .force;
  };
  EXPECT_LE(relativeError(forces.positionJacobian,
                          finiteDifferenceJacobian<N>(forceOfPositions, element.positions, step)),
            kTolerance);

  const Condition<N> condition = element.condition(element.positions, true);
  const auto forceOfVelocities = [&](const Positions<N>& v) -> Positions<N> {
    return elementForces(condition, stiffness, damping, v, StiffnessMode::Exact).force;
  };
  EXPECT_LE(relativeError(forces.velocityJacobian,
                          finiteDifferenceJacobian<N>(forceOfVelocities, velocities, 1e-6)),
            kTolerance);
}

/// Internal forces (elastic + damping) have zero sum and zero torque about the origin.
template <int N>
void expectMomentumConserved(const Case<N>& element, Random& random) {
  SCOPED_TRACE(element.name);
  Positions<N> velocities;
  for (int i = 0; i < 3 * N; ++i) {
    velocities[i] = random.uniform(-1, 1);
  }
  const ElementForces<N> forces = elementForces(element.condition(element.positions, false), 4.0,
                                                0.5, velocities, StiffnessMode::Exact);
  Vec3 total = Vec3::Zero(), torque = Vec3::Zero();
  Real forceScale = 0, torqueScale = 0;
  for (int i = 0; i < N; ++i) {
    const Vec3 x = element.positions.template segment<3>(3 * i);
    const Vec3 f = forces.force.template segment<3>(3 * i);
    total += f;
    torque += x.cross(f);
    forceScale += f.norm();
    torqueScale += x.norm() * f.norm();
  }
  ASSERT_GT(forceScale, 0) << "a test element with no force checks nothing";
  EXPECT_LE(total.norm(), 1e-12 * forceScale);
  EXPECT_LE(torque.norm(), 1e-12 * torqueScale);
}

/// C, and so the energy, is unchanged by a rigid rotation plus translation.
template <int N>
void expectRigidMotionInvariance(const Case<N>& element, Random& random) {
  SCOPED_TRACE(element.name);
  const Mat3 rotation = random.rotation();
  const Vec3 translation = random.vector(3);
  Positions<N> moved;
  for (int i = 0; i < N; ++i) {
    moved.template segment<3>(3 * i) =
        rotation * element.positions.template segment<3>(3 * i) + translation;
  }
  const Real before = element.condition(element.positions, false).value;
  const Real after = element.condition(moved, false).value;
  // C is accurate to rounding of the positions (~1e-12 absolute here, since a near-flat angle
  // is small but not relatively precise) on top of a 1e-10 relative error.
  const Real valueTolerance = 1e-10 * std::abs(before) + 1e-12;
  EXPECT_NEAR(after, before, valueTolerance);
  const Real stiffness = 2.5;
  EXPECT_NEAR(stiffness / 2 * after * after, stiffness / 2 * before * before,
              stiffness * (std::abs(before) + valueTolerance) * valueTolerance);
}

/// Smallest eigenvalue of a symmetric matrix relative to the largest magnitude.
template <int Dofs>
Real relativeSmallestEigenvalue(const Eigen::Matrix<Real, Dofs, Dofs>& matrix) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, Dofs, Dofs>> solver(matrix);
  const auto& eigenvalues = solver.eigenvalues();  // ascending
  const Real largest = std::max(std::abs(eigenvalues[0]), std::abs(eigenvalues[Dofs - 1]));
  return largest > 0 ? eigenvalues[0] / largest : 0;
}

/// Definite mode: −∂f/∂x symmetric positive semi-definite, with damping on and moving vertices.
template <int N>
void expectDefiniteModeSemiDefinite(const std::string& name,
                                    const std::vector<Condition<N>>& conditions,
                                    Random& random) {
  SCOPED_TRACE(name);
  Positions<N> velocities;
  for (int i = 0; i < 3 * N; ++i) {
    velocities[i] = random.uniform(-1, 1);
  }
  ElementForces<N> forces;
  for (const Condition<N>& condition : conditions) {
    accumulateConditionForces(condition, 7.0, 0.9, velocities, StiffnessMode::Definite, true,
                              forces);
  }
  const Eigen::Matrix<Real, 3 * N, 3 * N> stiffness = -forces.positionJacobian;
  ASSERT_GT(stiffness.norm(), 0);
  EXPECT_EQ(stiffness, stiffness.transpose());
  EXPECT_GE(relativeSmallestEigenvalue<3 * N>(stiffness), -1e-9);
  EXPECT_GE(relativeSmallestEigenvalue<3 * N>(-forces.velocityJacobian), -1e-9);
}

/// Exact mode (no damping, so the matrix is symmetric) is clearly indefinite.
template <int N>
Real exactModeRelativeSmallestEigenvalue(const Condition<N>& condition) {
  const ElementForces<N> forces =
      elementForces(condition, 7.0, 0, Positions<N>::Zero(), StiffnessMode::Exact);
  const Eigen::Matrix<Real, 3 * N, 3 * N> stiffness = -forces.positionJacobian;
  return relativeSmallestEigenvalue<3 * N>((stiffness + stiffness.transpose()) / 2);
}

template <int N>
bool allFinite(const Condition<N>& condition) {
  return std::isfinite(condition.value) && condition.gradient.allFinite() &&
         condition.hessian.allFinite();
}

template <int N>
bool allFinite(const ElementForces<N>& forces) {
  return std::isfinite(forces.energy) && forces.force.allFinite() &&
         forces.positionJacobian.allFinite() && forces.velocityJacobian.allFinite();
}

/// The condition and its forces in both modes are finite.
template <int N>
void expectFinite(const std::string& name, const Condition<N>& condition) {
  SCOPED_TRACE(name);
  EXPECT_TRUE(allFinite(condition));
  const Positions<N> velocities = Positions<N>::Constant(0.3);
  for (StiffnessMode mode : {StiffnessMode::Exact, StiffnessMode::Definite}) {
    EXPECT_TRUE(allFinite(elementForces(condition, 10.0, 1.0, velocities, mode)));
  }
}

// ---------------------------------------------------------------------------------------------
// makeTriangleRest

TEST(MakeTriangleRest, RightTriangleHasExpectedWeightsAndArea) {
  // u along x, v along y; legs 2 m (warp) and 1 m (weft).
  const TriangleRest rest = makeTriangleRest({4, 5, 6}, Vec2(0, 0), Vec2(2, 0), Vec2(0, 1));
  EXPECT_EQ(rest.vertices, (std::array<Index, 3>{4, 5, 6}));
  EXPECT_DOUBLE_EQ(rest.area, 1.0);
  EXPECT_DOUBLE_EQ(rest.warpWeights[0], -0.5);
  EXPECT_DOUBLE_EQ(rest.warpWeights[1], 0.5);
  EXPECT_DOUBLE_EQ(rest.warpWeights[2], 0.0);
  EXPECT_DOUBLE_EQ(rest.weftWeights[0], -1.0);
  EXPECT_DOUBLE_EQ(rest.weftWeights[1], 0.0);
  EXPECT_DOUBLE_EQ(rest.weftWeights[2], 1.0);

  // The identity map x = (u, v, 0) has w_u = (1, 0, 0) and w_v = (0, 1, 0).
  const Vec3 x0(0, 0, 0), x1(2, 0, 0), x2(0, 1, 0);
  const Vec3 warp = rest.warpWeights[0] * x0 + rest.warpWeights[1] * x1 + rest.warpWeights[2] * x2;
  const Vec3 weft = rest.weftWeights[0] * x0 + rest.weftWeights[1] * x1 + rest.weftWeights[2] * x2;
  EXPECT_EQ(warp, Vec3(1, 0, 0));
  EXPECT_EQ(weft, Vec3(0, 1, 0));
}

TEST(MakeTriangleRest, ClockwiseTriangleHasPositiveArea) {
  const TriangleRest rest = makeTriangleRest({0, 1, 2}, Vec2(0, 0), Vec2(0, 1), Vec2(2, 0));
  EXPECT_DOUBLE_EQ(rest.area, 1.0);
}

TEST(MakeTriangleRest, WeightsRecoverAnyAffineDeformationGradient) {
  Random random(3);
  for (int trial = 0; trial < 10; ++trial) {
    const auto uv = randomMaterialTriangle(random, random.uniform(0.01, 2));
    Eigen::Matrix<Real, 3, 2> deformation;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 2; ++j) {
        deformation(i, j) = random.uniform(-2, 2);
      }
    }
    const Vec3 translation = random.vector(5);
    const TriangleRest rest = makeTriangleRest({0, 1, 2}, uv[0], uv[1], uv[2]);
    Vec3 warp = Vec3::Zero(), weft = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      const Vec3 x = deformation * uv[i] + translation;
      warp += rest.warpWeights[i] * x;
      weft += rest.weftWeights[i] * x;
    }
    EXPECT_LE((warp - deformation.col(0)).norm(), 1e-12 * deformation.norm());
    EXPECT_LE((weft - deformation.col(1)).norm(), 1e-12 * deformation.norm());
    const Vec2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
    EXPECT_NEAR(rest.area, std::abs(d1.x() * d2.y() - d1.y() * d2.x()) / 2, 1e-15);
  }
}

// ---------------------------------------------------------------------------------------------
// Dihedral angle and hinge scale

TEST(DihedralAngle, SignedAngleFollowsTheHingeConvention) {
  // Edge x0 -> x1 along +x, A in z = 0 with n_A = +z; B folds about the edge.
  const Vec3 x0(0, 0, 0), x1(1, 0, 0), x2(0.3, 0.8, 0);
  const auto fold = [](Real angle) { return Vec3(0.6, -0.7 * std::cos(angle), 0.7 * std::sin(angle)); };
  EXPECT_EQ(dihedralAngle(x0, x1, x2, Vec3(0.6, -0.7, 0)), 0.0);
  for (Real angle : {1e-6, 0.3, 1.2, 2.5, kPi - 1e-6}) {
    // Positive when B folds towards A's normal, negative when it folds away.
    EXPECT_NEAR(dihedralAngle(x0, x1, x2, fold(angle)), angle, 1e-12);
    EXPECT_NEAR(dihedralAngle(x0, x1, x2, fold(-angle)), -angle, 1e-12);
  }
  // Folded flat onto A: +π, never −π.
  EXPECT_EQ(dihedralAngle(x0, x1, x2, Vec3(0.6, 0.7, 0)), kPi);
  EXPECT_EQ(dihedralAngle(x0, x1, x2, Vec3(0.6, 0.7, -0.0)), kPi);
  // Swapping the roles of A and B (and reversing the edge) keeps the angle.
  EXPECT_NEAR(dihedralAngle(x1, x0, fold(0.8), x2), 0.8, 1e-12);
}

TEST(DihedralAngle, IndependentOfTriangleShapeAndScale) {
  const Vec3 x0(0, 0, 0), x1(3, 0, 0);
  for (Real scale : {1e-3, 1.0, 50.0}) {
    const Vec3 x2 = scale * Vec3(-2.0, 0.1, 0);
    const Vec3 x3 = scale * Vec3(5.0, -4.0 * std::cos(0.7), 4.0 * std::sin(0.7));
    EXPECT_NEAR(dihedralAngle(scale * x0, scale * x1, x2, x3), 0.7, 1e-12);
  }
}

TEST(HingeStiffnessScale, IsThreeLengthSquaredOverAreaSum) {
  EXPECT_DOUBLE_EQ(hingeStiffnessScale(2.0, 1.0, 3.0), 3.0);
  EXPECT_DOUBLE_EQ(hingeStiffnessScale(0.05, 0.00125, 0.00125), 3.0);
  EXPECT_EQ(hingeStiffnessScale(1.0, 0.0, 0.0), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Derivatives

TEST(ForceKernels, StretchAndShearDerivativesMatchFiniteDifferences) {
  for (const Case<3>& element : triangleCases()) {
    expectDerivativesMatchFiniteDifferences(element);
  }
}

TEST(ForceKernels, BendDerivativesMatchFiniteDifferences) {
  for (const Case<4>& element : hingeCases()) {
    expectDerivativesMatchFiniteDifferences(element);
  }
}

TEST(ForceKernels, SpringDerivativesMatchFiniteDifferences) {
  for (const Case<2>& element : springCases()) {
    expectDerivativesMatchFiniteDifferences(element);
  }
}

TEST(ForceKernels, DampedForceJacobiansMatchFiniteDifferences) {
  Random random(17);
  for (const Case<3>& element : triangleCases()) {
    expectForceJacobiansMatchFiniteDifferences(element, random);
  }
  for (const Case<4>& element : hingeCases()) {
    expectForceJacobiansMatchFiniteDifferences(element, random);
  }
  for (const Case<2>& element : springCases()) {
    expectForceJacobiansMatchFiniteDifferences(element, random);
  }
}

TEST(ForceKernels, BendConditionIsScaledWrappedAngle) {
  Random random(19);
  const Positions<4> flat = hingePositions(random, 0, 0.05, 0);
  for (Real restAngle : {0.0, 0.6, -2.0, kPi - 0.1}) {
    const Hinge hinge = hingeFor(flat, restAngle);
    ASSERT_GT(hinge.stiffnessScale, 0);
    for (Real angle : {0.4, -1.1, 3.0, -3.0}) {
      const Positions<4> x = hingePositions(random, angle, 0.05, 0);
      Real expected = angle - restAngle;
      expected = expected > kPi ? expected - 2 * kPi : expected <= -kPi ? expected + 2 * kPi : expected;
      EXPECT_NEAR(bendConditionOf(hinge)(x, false).value, std::sqrt(hinge.stiffnessScale) * expected,
                  1e-10);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Physical invariants

TEST(ForceKernels, RestPoseHasZeroEnergyAndForce) {
  Random random(23);
  const auto expectAtRest = [](const std::string& name, const auto& condition) {
    SCOPED_TRACE(name);
    constexpr int kN = std::decay_t<decltype(condition)>::kVertexCount;
    const auto forces = elementForces(condition, 100.0, 1.0, Positions<kN>::Zero(),
                                      StiffnessMode::Exact);
    EXPECT_NEAR(condition.value, 0, 1e-12);
    EXPECT_LE(forces.energy, 1e-20);
    EXPECT_LE(forces.force.norm(), 1e-10);
  };

  for (Real size : {1.0, 0.05}) {
    // Stretch and shear: the material triangle rigidly placed in space, b_u = b_v = 1.
    const TriangleSetup setup =
        placeTriangle(randomMaterialTriangle(random, size), planarDeformation(1, 0, 0, 1),
                      random.rotation(), random.vector(2), random, 0, size);
    const auto& x = setup.positions;
    const StretchConditions stretch = stretchConditions(x.segment<3>(0), x.segment<3>(3),
                                                        x.segment<3>(6), setup.rest, 1, 1, true);
    expectAtRest("warp", stretch.warp);
    expectAtRest("weft", stretch.weft);
    expectAtRest("shear", shearCondition(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6),
                                         setup.rest, true));

    // Bend: flat with θ_rest = 0, and curved rest hinges at their rest angle.
    for (Real restAngle : {0.0, 0.8, -1.9, kPi - 0.01}) {
      const Positions<4> hinge = hingePositions(random, restAngle, size, 0);
      expectAtRest("bend rest " + std::to_string(restAngle),
                   bendConditionOf(hingeFor(hinge, restAngle))(hinge, true));
    }

    // Spring at its rest length.
    const Vec3 x0 = random.vector(2);
    expectAtRest("spring", springCondition(x0, x0 + size * (random.rotation() * Vec3::UnitX()),
                                           size, true));
  }
}

TEST(ForceKernels, StretchAndShearEnergyIsAreaTimesEnergyDensity) {
  // Uniform deformation w_u = (s_u, 0, 0), w_v = (γ, s_v, 0): E = k a/2 (|w| − b)² per condition,
  // so k is in N/m and the energy of a sheet does not depend on how finely it is meshed.
  const Real stiffness = 260.0;
  const Real su = 1.1, sv = 0.95, gamma = 0.2;
  for (Real size : {1.0, 0.05}) {
    const TriangleRest rest = makeTriangleRest({0, 1, 2}, Vec2(0, 0), Vec2(size, 0), Vec2(0, size));
    const Vec3 x0(0, 0, 0), x1(su * size, 0, 0), x2(gamma * size, sv * size, 0);
    const StretchConditions stretch = stretchConditions(x0, x1, x2, rest, 1, 1, false);
    const Condition<3> shear = shearCondition(x0, x1, x2, rest, false);
    ElementForces<3> forces;
    for (const Condition<3>* condition : {&stretch.warp, &stretch.weft, &shear}) {
      accumulateConditionForces(*condition, stiffness, 0, Positions<3>::Zero(),
                                StiffnessMode::Definite, false, forces);
    }
    const Real area = size * size / 2;
    const Real weftStretch = std::hypot(gamma, sv);
    const Real expected = stiffness * area / 2 *
                          ((su - 1) * (su - 1) + (weftStretch - 1) * (weftStretch - 1) +
                           (su * gamma) * (su * gamma));
    EXPECT_NEAR(forces.energy, expected, 1e-12 * expected) << "size " << size;
  }
}

TEST(ForceKernels, EnergyInvariantUnderRigidMotion) {
  Random random(29);
  for (const Case<3>& element : triangleCases()) {
    expectRigidMotionInvariance(element, random);
  }
  for (const Case<4>& element : hingeCases()) {
    expectRigidMotionInvariance(element, random);
  }
  for (const Case<2>& element : springCases()) {
    expectRigidMotionInvariance(element, random);
  }
}

TEST(ForceKernels, InternalForcesConserveLinearAndAngularMomentum) {
  Random random(31);
  for (const Case<3>& element : triangleCases()) {
    expectMomentumConserved(element, random);
  }
  for (const Case<4>& element : hingeCases()) {
    expectMomentumConserved(element, random);
  }
  for (const Case<2>& element : springCases()) {
    expectMomentumConserved(element, random);
  }
}

// ---------------------------------------------------------------------------------------------
// Stiffness modes

TEST(ForceKernels, DefiniteModeIsPositiveSemiDefinite) {
  Random random(37);
  const auto uv = randomMaterialTriangle(random, 0.05);
  // Compressed, stretched, sheared, anisotropic, and bent out of plane with noise.
  const std::vector<std::pair<std::string, Eigen::Matrix<Real, 3, 2>>> deformations = {
      {"compressed", planarDeformation(0.6, 0, 0, 0.7)},
      {"stretched", planarDeformation(1.3, 0, 0, 1.2)},
      {"sheared", planarDeformation(1, 0.6, 0.1, 1)},
      {"warp stretched, weft compressed", planarDeformation(1.2, 0, 0, 0.5)},
  };
  for (const auto& [name, deformation] : deformations) {
    const TriangleSetup setup =
        placeTriangle(uv, deformation, random.rotation(), random.vector(1), random, 0.05, 0.05);
    const auto& x = setup.positions;
    const StretchConditions stretch = stretchConditions(
        x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), setup.rest, 1, 1, true);
    const Condition<3> shear =
        shearCondition(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), setup.rest, true);
    expectDefiniteModeSemiDefinite<3>(name + " warp", {stretch.warp}, random);
    expectDefiniteModeSemiDefinite<3>(name + " weft", {stretch.weft}, random);
    expectDefiniteModeSemiDefinite<3>(name + " shear", {shear}, random);
    expectDefiniteModeSemiDefinite<3>(name + " triangle", {stretch.warp, stretch.weft, shear},
                                      random);
  }
  for (Real angle : {0.3, 1.5, -2.5, kPi - 1e-3}) {
    const Positions<4> x = hingePositions(random, angle, 0.05, 0.05);
    expectDefiniteModeSemiDefinite<4>("folded " + std::to_string(angle),
                                      {bendConditionOf(hingeFor(x, 0))(x, true)}, random);
  }
  for (const Case<2>& element : springCases()) {
    expectDefiniteModeSemiDefinite<2>(element.name, {element.condition(element.positions, true)},
                                      random);
  }
}

TEST(ForceKernels, ExactModeIsIndefiniteWhereDefiniteModeIsNot) {
  Random random(41);
  // Compressed stretch: −k C ∇²C with C < 0 is negative across the fibre.
  const auto uv = randomMaterialTriangle(random, 0.05);
  const TriangleSetup compressed = placeTriangle(uv, planarDeformation(0.6, 0, 0, 0.7),
                                                 random.rotation(), random.vector(1), random, 0, 0.05);
  const auto& x = compressed.positions;
  const StretchConditions stretch = stretchConditions(x.segment<3>(0), x.segment<3>(3),
                                                      x.segment<3>(6), compressed.rest, 1, 1, true);
  EXPECT_LT(exactModeRelativeSmallestEigenvalue(stretch.warp), -1e-3);

  // Sheared triangle: the shear Hessian is a saddle.
  const TriangleSetup sheared = placeTriangle(uv, planarDeformation(1, 0.6, 0, 1),
                                              random.rotation(), random.vector(1), random, 0, 0.05);
  const auto& y = sheared.positions;
  EXPECT_LT(exactModeRelativeSmallestEigenvalue(
                shearCondition(y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), sheared.rest, true)),
            -1e-3);

  // Strongly folded hinge.
  const Positions<4> folded = hingePositions(random, 2.0, 0.05, 0);
  EXPECT_LT(exactModeRelativeSmallestEigenvalue(bendConditionOf(hingeFor(folded, 0))(folded, true)),
            -1e-3);

  // Compressed spring.
  EXPECT_LT(exactModeRelativeSmallestEigenvalue(
                springCondition(Vec3(0, 0, 0), Vec3(0.5, 0, 0), 1.0, true)),
            -1e-3);
}

TEST(ForceKernels, DefiniteModeKeepsStretchedGeometricStiffnessOnly) {
  // A stretched spring keeps k C ∇²C (lateral stiffness); a compressed one drops it.
  const Condition<2> stretched = springCondition(Vec3(0, 0, 0), Vec3(1.5, 0, 0), 1.0, true);
  const Condition<2> compressed = springCondition(Vec3(0, 0, 0), Vec3(0.5, 0, 0), 1.0, true);
  const auto lateral = [](const Condition<2>& condition, StiffnessMode mode) {
    return -elementForces(condition, 10.0, 0, Positions<2>::Zero(), mode).positionJacobian(1, 1);
  };
  EXPECT_NEAR(lateral(stretched, StiffnessMode::Definite), 10.0 * 0.5 / 1.5, 1e-12);
  EXPECT_EQ(lateral(stretched, StiffnessMode::Definite), lateral(stretched, StiffnessMode::Exact));
  EXPECT_EQ(lateral(compressed, StiffnessMode::Definite), 0.0);
  EXPECT_LT(lateral(compressed, StiffnessMode::Exact), 0.0);
}

TEST(ForceKernels, DampingActsOnRelativeVelocityAlongTheSpring) {
  const Condition<2> spring = springCondition(Vec3(0, 0, 0), Vec3(2, 0, 0), 2.0, false);
  Positions<2> velocities;
  velocities << 0, 5, 0, 1, 7, 0;  // separating at 1 m/s along x; sideways motion is free
  ElementForces<2> forces;
  accumulateConditionForces(spring, 100.0, 3.0, velocities, StiffnessMode::Definite, false, forces);
  Positions<2> expected;
  expected << 3.0, 0, 0, -3.0, 0, 0;
  EXPECT_LE((forces.force - expected).norm(), 1e-12);
  EXPECT_EQ(forces.energy, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Degenerate input

TEST(ForceKernels, DegenerateInputGivesFiniteResults) {
  const TriangleRest rest = makeTriangleRest({0, 1, 2}, Vec2(0, 0), Vec2(0.05, 0), Vec2(0, 0.05));
  const Vec3 p(0.3, -0.2, 0.1);
  const auto triangle = [&](const std::string& name, const Vec3& x0, const Vec3& x1,
                            const Vec3& x2) {
    const StretchConditions stretch = stretchConditions(x0, x1, x2, rest, 1, 1, true);
    expectFinite(name + " warp", stretch.warp);
    expectFinite(name + " weft", stretch.weft);
    expectFinite(name + " shear", shearCondition(x0, x1, x2, rest, true));
  };
  triangle("collapsed to a point", p, p, p);
  triangle("collinear", p, p + Vec3(0.05, 0, 0), p + Vec3(0.1, 0, 0));
  triangle("warp collapsed", p, p, p + Vec3(0, 0.05, 0));
  {
    const StretchConditions stretch = stretchConditions(p, p, p, rest, 1, 1, true);
    EXPECT_NEAR(stretch.warp.value, -std::sqrt(rest.area), 1e-15);
  }

  const Vec3 a(0, 0, 0), b(0.05, 0, 0), c(0.02, 0.04, 0), d(0.03, -0.04, 0.01);
  Hinge hinge;
  hinge.restAngle = 0.3;
  hinge.stiffnessScale = 3.0;
  const auto bend = [&](const std::string& name, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                        const Vec3& x3) {
    const Condition<4> condition = bendCondition(x0, x1, x2, x3, hinge, true);
    expectFinite(name, condition);
    EXPECT_TRUE(std::isfinite(dihedralAngle(x0, x1, x2, x3))) << name;
  };
  bend("collapsed edge", a, a, c, d);
  bend("A has zero area", a, b, Vec3(0.1, 0, 0), d);
  bend("B has zero area", a, b, c, Vec3(-0.02, 0, 0));
  bend("x3 on x0", a, b, c, a);
  bend("all at one point", a, a, a, a);
  bend("nearly collapsed edge", a, Vec3(1e-12, 0, 0), c, d);
  bend("sliver A", a, b, Vec3(0.02, 1e-13, 0), d);
  EXPECT_EQ(bendCondition(a, a, c, d, hinge, true).gradient, Condition<4>::Gradient::Zero());

  expectFinite("spring collapsed", springCondition(p, p, 0.05, true));
  expectFinite("zero-length spring collapsed", springCondition(p, p, 0, true));
  expectFinite("zero-length spring, tiny extension",
               springCondition(p, p + Vec3(1e-300, 0, 0), 0, true));
}

TEST(ForceKernels, ACollapsedStretchFibreIsPushedOpenAcrossTheOther) {
  // A fibre collapsed to a point has no direction; the kernel gives it one (BaraffWitkin.h), the
  // same for every triangle, so that a cloth collapsed onto a point or a line opens again.
  const TriangleRest rest = makeTriangleRest({0, 1, 2}, Vec2(0, 0), Vec2(0.05, 0), Vec2(0, 0.05));
  const Real sqrtArea = std::sqrt(rest.area);
  const auto expectAlong = [&](const Condition<3>& condition, const std::array<Real, 3>& weights,
                               const Vec3& direction, const std::string& name) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE((condition.gradient.segment<3>(3 * i) - sqrtArea * weights[i] * direction).norm(),
                1e-12) << name << ", vertex " << i;
    }
    EXPECT_EQ(condition.hessian, Condition<3>::Hessian::Zero()) << name;
  };
  const Vec3 p(0.3, -0.2, 0.1);
  // On one point: warp along x, weft along y.
  const StretchConditions point = stretchConditions(p, p, p, rest, 1, 1, true);
  expectAlong(point.warp, rest.warpWeights, Vec3::UnitX(), "point, warp");
  expectAlong(point.weft, rest.weftWeights, Vec3::UnitY(), "point, weft");
  // On a line along z (the warp fibre intact): the weft across it, along the world axis least
  // aligned with it (x).
  const StretchConditions line = stretchConditions(p, p + Vec3(0, 0, 0.05), p, rest, 1, 1, true);
  expectAlong(line.weft, rest.weftWeights, Vec3::UnitX(), "line, weft");
  EXPECT_GT(line.warp.gradient.segment<3>(3).z(), 0.0);  // the intact fibre as before
  // The force −k C ∇C (C < 0) opens the collapsed fibre: a small step along it gives |w| > 0 and
  // lowers the energy k/2 C².
  const Condition<3>& weft = line.weft;
  std::array<Vec3, 3> x{p, p + Vec3(0, 0, 0.05), p};
  for (int i = 0; i < 3; ++i) x[i] -= 1e-4 * weft.value * weft.gradient.segment<3>(3 * i);
  const StretchConditions opened = stretchConditions(x[0], x[1], x[2], rest, 1, 1, false);
  EXPECT_GT(opened.weft.value, weft.value);
  EXPECT_LT(opened.weft.value * opened.weft.value, weft.value * weft.value);
}

// ---------------------------------------------------------------------------------------------
// stretchShear: the three membrane conditions fused for the implicit step

/// The reference the fused kernel must reproduce: the warp, weft and shear conditions through
/// accumulateConditionForces in Definite mode, as one 9×9 element.
struct MembraneReference {
  Real energy = 0;
  Positions<3> force, product;
  Eigen::Matrix<Real, 9, 9> system;  // −h ∂f/∂v − h² ∂f/∂x
};

MembraneReference membraneReference(const Positions<3>& x, const Positions<3>& v,
                                    const Positions<3>& u, const TriangleRest& rest,
                                    const std::array<Real, 2>& restScales,
                                    const StretchShearCoefficients& k, Real h) {
  const Vec3 x0 = x.segment<3>(0), x1 = x.segment<3>(3), x2 = x.segment<3>(6);
  const StretchConditions stretch =
      stretchConditions(x0, x1, x2, rest, restScales[0], restScales[1], true);
  ElementForces<3> forces;
  const StiffnessMode mode = StiffnessMode::Definite;
  accumulateConditionForces(stretch.warp, k.warpStiffness, k.stretchDamping, v, mode, true, forces);
  accumulateConditionForces(stretch.weft, k.weftStiffness, k.stretchDamping, v, mode, true, forces);
  accumulateConditionForces(shearCondition(x0, x1, x2, rest, true), k.shearStiffness,
                            k.shearDamping, v, mode, true, forces);
  return {forces.energy, forces.force, forces.positionJacobian * u,
          -h * forces.velocityJacobian - h * h * forces.positionJacobian};
}

/// The fused kernel's outputs in the reference's layout.
struct MembraneFused {
  Real energy = 0;
  Positions<3> force, product;
  Eigen::Matrix<Real, 9, 9> system;
};

MembraneFused membraneFused(const Positions<3>& x, const Positions<3>& v, const Positions<3>& u,
                            const StretchShearRest& rest, const StretchShearCoefficients& k,
                            Real h, bool withSystem = true) {
  const auto corners = [](const Positions<3>& p) {
    return std::array<Vec3, 3>{p.segment<3>(0), p.segment<3>(3), p.segment<3>(6)};
  };
  const StretchShearTerms terms = stretchShear(corners(x), corners(v), corners(u), rest, k, h, withSystem);
  MembraneFused out;
  out.energy = terms.energy;
  for (int i = 0; i < 3; ++i) {
    out.force.segment<3>(3 * i) = terms.force[i];
    if (!withSystem) continue;
    out.product.segment<3>(3 * i) = terms.stiffnessTimesVelocity[i];
    for (int j = 0; j < 3; ++j) {
      Mat3 block = Mat3::Zero();
      addStretchShearBlock(terms, rest, i, j, block);
      out.system.block<3, 3>(3 * i, 3 * j) = block;
    }
  }
  return out;
}

Positions<3> randomVelocities(Random& random, Real amplitude) {
  Positions<3> v;
  for (int i = 0; i < 9; ++i) v[i] = random.uniform(-amplitude, amplitude);
  return v;
}

TEST(StretchShear, MatchesTheConditionsInDefiniteMode) {
  // Random stretched, compressed and sheared triangles at two scales, with damping, rest scales
  // other than 1 and a product vector u other than v: the closed form agrees with the sum of the
  // three conditions to rounding.
  Random random(41);
  const StretchShearCoefficients k{260, 180, 100, 0.5, 0.2};
  const std::array<Real, 2> restScales{0.97, 1.02};
  const Real h = 1.0 / 60;
  int stretchedWarp = 0, compressedWarp = 0;
  for (Real size : {1.0, 0.05}) {
    for (int trial = 0; trial < 40; ++trial) {
      const TriangleSetup setup = randomTriangle(random, size);
      const Positions<3> v = randomVelocities(random, 1), u = randomVelocities(random, 1);
      const MembraneReference reference =
          membraneReference(setup.positions, v, u, setup.rest, restScales, k, h);
      const StretchShearRest rest = makeStretchShearRest(setup.rest, restScales[0], restScales[1]);
      const MembraneFused fused = membraneFused(setup.positions, v, u, rest, k, h);
      const std::string name = "size " + std::to_string(size) + " trial " + std::to_string(trial);
      EXPECT_NEAR(fused.energy, reference.energy, 1e-12 * reference.energy) << name;
      EXPECT_LT(relativeError(fused.force, reference.force), 1e-12) << name;
      EXPECT_LT(relativeError(fused.product, reference.product), 1e-12) << name;
      EXPECT_LT(relativeError(fused.system, reference.system), 1e-12) << name;
      // Forces alone are the same bits as with the system.
      EXPECT_EQ(membraneFused(setup.positions, v, u, rest, k, h, false).force, fused.force) << name;
      const Real warpLength = (setup.rest.warpWeights[0] * setup.positions.segment<3>(0) +
                               setup.rest.warpWeights[1] * setup.positions.segment<3>(3) +
                               setup.rest.warpWeights[2] * setup.positions.segment<3>(6)).norm();
      (warpLength > restScales[0] ? stretchedWarp : compressedWarp) += 1;
    }
  }
  // Both branches of the geometric stiffness were exercised.
  EXPECT_GT(stretchedWarp, 10);
  EXPECT_GT(compressedWarp, 10);
}

TEST(StretchShear, DerivativesMatchFiniteDifferences) {
  // Where Definite is exact (both fibres stretched, warp ⟂ weft so the shear condition is zero,
  // v = 0 so no damping term depends on x): −h ∂f/∂v − h² ∂f/∂x and (∂f/∂x)·u from central
  // differences of the force, and the force from those of the energy.
  Random random(43);
  const StretchShearCoefficients k{260, 180, 100, 0.5, 0.2};
  const Real h = 1.0 / 60;
  for (Real size : {1.0, 0.05}) {
    for (int trial = 0; trial < 10; ++trial) {
      const std::array<Vec2, 3> uv = randomMaterialTriangle(random, size);
      const TriangleSetup setup =
          placeTriangle(uv, planarDeformation(1 + random.uniform(0.05, 0.3), 0, 0,
                                              1 + random.uniform(0.05, 0.3)),
                        random.rotation(), random.vector(2), random, 0, size);
      const StretchShearRest rest = makeStretchShearRest(setup.rest, 1, 1);
      const Positions<3> zero = Positions<3>::Zero(), u = randomVelocities(random, 1);
      const Real step = kRelativeStep * size;
      const std::function<Real(const Positions<3>&)> energy = [&](const Positions<3>& x) {
        return membraneFused(x, zero, zero, rest, k, h, false).energy;
      };
      const std::function<Positions<3>(const Positions<3>&)> forceOfX =
          [&](const Positions<3>& x) { return membraneFused(x, zero, zero, rest, k, h, false).force; };
      const std::function<Positions<3>(const Positions<3>&)> forceOfV =
          [&](const Positions<3>& v) {
            return membraneFused(setup.positions, v, zero, rest, k, h, false).force;
          };
      const MembraneFused fused = membraneFused(setup.positions, zero, u, rest, k, h);
      const auto positionJacobian = finiteDifferenceJacobian<3>(forceOfX, setup.positions, step);
      const auto velocityJacobian = finiteDifferenceJacobian<3>(forceOfV, zero, 1e-6);
      const std::string name = "size " + std::to_string(size) + " trial " + std::to_string(trial);
      EXPECT_LT(relativeError(fused.force,
                              -finiteDifferenceGradient<3>(energy, setup.positions, step)),
                kTolerance) << name;
      EXPECT_LT(relativeError(fused.system, -h * velocityJacobian - h * h * positionJacobian),
                kTolerance) << name;
      EXPECT_LT(relativeError(fused.product, positionJacobian * u), kTolerance) << name;
    }
  }
}

TEST(StretchShear, SystemBlocksAreSymmetricToTheBit) {
  // The assembled matrix must be symmetric to the bit: block (j, i) is block (i, j) transposed,
  // and X_vu is X_uv transposed.
  Random random(47);
  const StretchShearCoefficients k{260, 260, 100, 0.5, 0.2};
  for (int trial = 0; trial < 20; ++trial) {
    const TriangleSetup setup = randomTriangle(random, 0.05);
    const StretchShearRest rest = makeStretchShearRest(setup.rest, 1, 1);
    const Positions<3> v = randomVelocities(random, 1);
    const MembraneFused fused = membraneFused(setup.positions, v, v, rest, k, 1.0 / 60);
    EXPECT_EQ(fused.system, fused.system.transpose()) << "trial " << trial;
    const std::array<Vec3, 3> x{setup.positions.segment<3>(0), setup.positions.segment<3>(3),
                                setup.positions.segment<3>(6)};
    const StretchShearTerms terms =
        stretchShear(x, x, x, rest, k, 1.0 / 60, true);
    EXPECT_EQ(terms.weftWarp, terms.warpWeft.transpose()) << "trial " << trial;
  }
}

TEST(StretchShear, CollapsedFibresMatchTheConditions) {
  // A triangle on one point, and on a line along either fibre: the fallback directions, and no
  // curvature term, exactly as the conditions have them.
  const TriangleRest triangle = makeTriangleRest({0, 1, 2}, Vec2(0, 0), Vec2(0.05, 0), Vec2(0, 0.05));
  const StretchShearRest rest = makeStretchShearRest(triangle, 1, 1);
  const StretchShearCoefficients k{260, 180, 100, 0.5, 0.2};
  const Real h = 1.0 / 60;
  Random random(53);
  const Vec3 p(0.3, -0.2, 0.1), along(0, 0, 0.05);
  const std::array<std::pair<std::string, Positions<3>>, 3> cases{{
      {"point", (Positions<3>() << p, p, p).finished()},
      {"weft collapsed", (Positions<3>() << p, p + along, p).finished()},
      {"warp collapsed", (Positions<3>() << p, p, p + along).finished()},
  }};
  for (const auto& [name, x] : cases) {
    const Positions<3> v = randomVelocities(random, 1), u = randomVelocities(random, 1);
    const MembraneReference reference = membraneReference(x, v, u, triangle, {1, 1}, k, h);
    const MembraneFused fused = membraneFused(x, v, u, rest, k, h);
    EXPECT_NEAR(fused.energy, reference.energy, 1e-12 * reference.energy) << name;
    EXPECT_LT(relativeError(fused.force, reference.force), 1e-12) << name;
    EXPECT_LT(relativeError(fused.product, reference.product), 1e-12) << name;
    EXPECT_LT(relativeError(fused.system, reference.system), 1e-12) << name;
  }
}

}  // namespace
}  // namespace weft
