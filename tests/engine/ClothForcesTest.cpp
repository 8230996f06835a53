// ClothForces' assembly of a whole cloth in StiffnessMode::Definite (the implicit solver's): the
// fused membrane kernel (stretchShear) against the three conditions summed per triangle, and the
// assembly's contract: every bit the same on 1 and 2 threads, the matrix symmetric to the bit, and
// nothing left of the matrix's previous values (the per-vertex pass starts every row).
#include <ClothForces.h>
#include <forces/BaraffWitkin.h>
#include <forces/Condition.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

namespace weft {
namespace {

constexpr Real kStep = 1.0 / 60;  // s

ClothModel gridModel() {
  GridSettings grid;
  grid.columns = 31;  // 1,800 triangles: several reduction blocks per colour on 2 threads
  grid.rows = 31;
  grid.width = 0.6;
  grid.height = 0.6;
  return ClothModel::grid(grid).value();
}

// A stretched, compressed and sheared state with random velocities.
struct RandomState {
  Vec3Array x, v, u;
  RandomState(const ClothModel& model, unsigned seed) {
    std::mt19937 random(seed);
    std::normal_distribution<Real> position(0, 0.004), velocity(0, 0.3);
    for (const Vec3& p : model.restPositions()) {
      x.push_back(Vec3(1.05 * p.x(), 0.97 * p.y(), p.z()) +
                  Vec3(position(random), position(random), position(random)));
      v.emplace_back(velocity(random), velocity(random), velocity(random));
      u.emplace_back(velocity(random), velocity(random), velocity(random));
    }
  }
};

Real relativeError(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected) {
  return (actual - expected).norm() / std::max({actual.norm(), expected.norm(), Real(1e-300)});
}

Eigen::VectorXd flat(const Vec3Array& vectors) {
  Eigen::VectorXd out(3 * vectors.size());
  for (std::size_t i = 0; i < vectors.size(); ++i) out.segment<3>(3 * i) = vectors[i];
  return out;
}

TEST(ClothForces, TheFusedMembraneMatchesTheConditionsSummedPerTriangle) {
  // Membrane only (no bending, gravity or drag), so the reference is the warp, weft and shear
  // conditions of every triangle through accumulateConditionForces in Definite mode.
  const ClothModel model = gridModel();
  ClothForceSettings settings;
  settings.material.bendingStiffness = settings.material.bendingDamping = 0;
  settings.material.airDrag = 0;
  settings.material.warpRestScale = 0.98;
  settings.gravity = Vec3::Zero();
  const ClothMaterial& material = settings.material;
  const std::vector<Real> masses = model.vertexMasses(material.arealDensity);
  ClothForces forces(model, settings, masses);
  BlockSparseMatrix matrix;
  matrix.build(model.vertexCount(), forces.coupledPairs());
  forces.bindMatrix(matrix);
  const RandomState state(model, 7);
  Vec3Array f, product;
  const Real energy = forces.assemble(state.x, state.v, kStep, matrix, f, state.u, product);

  const Index n = model.vertexCount();
  Eigen::MatrixXd massMatrix = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (Index i = 0; i < n; ++i) massMatrix.block<3, 3>(3 * i, 3 * i) = masses[i] * Mat3::Identity();
  Eigen::MatrixXd system = massMatrix;
  Eigen::VectorXd referenceForce = Eigen::VectorXd::Zero(3 * n);
  Eigen::VectorXd referenceProduct = Eigen::VectorXd::Zero(3 * n);
  Real referenceEnergy = 0;
  for (const TriangleRest& rest : model.triangles()) {
    const auto& corner = rest.vertices;
    const Vec3 &x0 = state.x[corner[0]], &x1 = state.x[corner[1]], &x2 = state.x[corner[2]];
    Eigen::Matrix<Real, 9, 1> v, u;
    for (int a = 0; a < 3; ++a) {
      v.segment<3>(3 * a) = state.v[corner[a]];
      u.segment<3>(3 * a) = state.u[corner[a]];
    }
    const StiffnessMode mode = StiffnessMode::Definite;
    const StretchConditions stretch = stretchConditions(x0, x1, x2, rest, material.warpRestScale,
                                                        material.weftRestScale, true);
    ElementForces<3> local;
    accumulateConditionForces(stretch.warp, material.warpStretchStiffness,
                              material.stretchDamping, v, mode, true, local);
    accumulateConditionForces(stretch.weft, material.weftStretchStiffness,
                              material.stretchDamping, v, mode, true, local);
    accumulateConditionForces(shearCondition(x0, x1, x2, rest, false), material.shearStiffness,
                              material.shearDamping, v, mode, true, local);
    referenceEnergy += local.energy;
    const Eigen::Matrix<Real, 9, 9> block =
        -kStep * local.velocityJacobian - kStep * kStep * local.positionJacobian;
    const Eigen::Matrix<Real, 9, 1> localProduct = local.positionJacobian * u;
    for (int a = 0; a < 3; ++a) {
      referenceForce.segment<3>(3 * corner[a]) += local.force.segment<3>(3 * a);
      referenceProduct.segment<3>(3 * corner[a]) += localProduct.segment<3>(3 * a);
      for (int b = 0; b < 3; ++b) {
        system.block<3, 3>(3 * corner[a], 3 * corner[b]) += block.block<3, 3>(3 * a, 3 * b);
      }
    }
  }
  EXPECT_NEAR(energy, referenceEnergy, 1e-12 * referenceEnergy);
  EXPECT_LT(relativeError(flat(f), referenceForce), 1e-12);
  EXPECT_LT(relativeError(flat(product), referenceProduct), 1e-12);
  const Eigen::MatrixXd assembled(matrix.toEigen());
  // −h ∂f/∂v − h² ∂f/∂x alone: the masses would hide its errors.
  EXPECT_LT(relativeError(assembled - massMatrix, system - massMatrix), 1e-12);
  // Forces alone are those of the assembly, to the bit.
  Vec3Array forcesOnly;
  EXPECT_EQ(forces.computeForces(state.x, state.v, forcesOnly), energy);
  EXPECT_EQ(forcesOnly, f);
}

// One assembly of the full material (isometric bending, gravity, drag) with the pinned top row
// removed from the system, into a matrix and coupling that first hold NaN.
struct PinnedAssembly {
  FreeVertexMap map;
  BlockSparseMatrix matrix;
  PinnedCoupling coupling;
  Vec3Array f, product;
  Real energy = 0;

  PinnedAssembly(const ClothModel& model, const RandomState& state, int threads) {
    TaskSystem tasks(TaskSystemSettings{threads});
    ClothForceSettings settings;
    ClothForces forces(model, settings, model.vertexMasses(settings.material.arealDensity), &tasks);
    std::vector<Index> pinned;
    const Index columns = model.gridSize()[0], rows = model.gridSize()[1];
    for (Index c = 0; c < columns; ++c) pinned.push_back((rows - 1) * columns + c);
    map.build(model.vertexCount(), pinned);
    const std::vector<std::array<Index, 2>> pairs = forces.coupledPairs();
    std::vector<std::array<Index, 2>> rowPairs;
    for (const auto& [i, j] : pairs) {
      if (map.row(i) != kInvalidIndex && map.row(j) != kInvalidIndex) {
        rowPairs.push_back({map.row(i), map.row(j)});
      }
    }
    matrix.build(map.rowCount(), rowPairs);
    coupling.build(map, pairs);
    forces.bindMatrix(matrix, map, coupling);
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    for (Index slot = 0; slot < matrix.blockCount(); ++slot) matrix.block(slot).setConstant(nan);
    for (Index slot = 0; slot < coupling.blockCount(); ++slot) coupling.block(slot).setConstant(nan);
    energy = forces.assemble(state.x, state.v, kStep, matrix, f, state.u, product, &coupling);
  }
};

TEST(ClothForces, AssemblyIsBitwiseTheSameOnOneAndTwoThreadsSymmetricAndStartsEveryBlock) {
  const ClothModel model = gridModel();
  const RandomState state(model, 11);
  const PinnedAssembly serial(model, state, 1), parallel(model, state, 2);
  const Eigen::MatrixXd matrix(serial.matrix.toEigen());
  EXPECT_FALSE(matrix.array().isNaN().any()) << "a matrix block kept its old value";
  for (Index slot = 0; slot < serial.coupling.blockCount(); ++slot) {
    EXPECT_FALSE(serial.coupling.block(slot).array().isNaN().any()) << "coupling slot " << slot;
    EXPECT_EQ(serial.coupling.block(slot), parallel.coupling.block(slot)) << "coupling slot " << slot;
  }
  // Compared as a whole (a failing EXPECT_EQ would print both 2,883² matrices).
  EXPECT_TRUE(matrix == matrix.transpose()) << "not symmetric to the bit";
  EXPECT_TRUE(matrix == Eigen::MatrixXd(parallel.matrix.toEigen())) << "differs on 2 threads";
  EXPECT_EQ(serial.f, parallel.f);
  EXPECT_EQ(serial.product, parallel.product);
  EXPECT_EQ(serial.energy, parallel.energy);
}

}  // namespace
}  // namespace weft
