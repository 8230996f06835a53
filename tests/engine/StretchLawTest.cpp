// The biphasic stretch law (forces/StretchLaw.h) alone: its tension is the derivative of its
// energy and its tangent the derivative of its tension (central differences), both continuous at
// the knee and at twice the knee; below the knee a triangle's forces are the linear law's, bit
// for bit; above it the element forces are the energy's gradient and the exact Jacobian its
// derivative; the validation names the field at fault.
#include <forces/BaraffWitkin.h>
#include <forces/StretchLaw.h>

#include <weft/engine/FabricPresets.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <limits>

namespace weft {
namespace {

using ::testing::HasSubstr;

constexpr StretchLaw kLaw{260.0, 0.02, 24000.0};  // N/m, strain, N/m

TEST(StretchLaw, TensionAndTangentAreTheDerivativesOfEnergyAndTension) {
  const Real step = 1e-7;
  for (Real strain : {-0.05, 0.005, 0.019, 0.025, 0.031, 0.039, 0.041, 0.08, 0.2}) {
    const StretchResponse at = stretchResponse(kLaw, strain);
    const StretchResponse plus = stretchResponse(kLaw, strain + step);
    const StretchResponse minus = stretchResponse(kLaw, strain - step);
    EXPECT_NEAR(at.tension, (plus.energyDensity - minus.energyDensity) / (2 * step),
                1e-6 * std::max(1.0, std::abs(at.tension)))
        << "strain " << strain;
    EXPECT_NEAR(at.tangent, (plus.tension - minus.tension) / (2 * step),
                1e-5 * std::max(1.0, at.tangent))
        << "strain " << strain;
  }
}

TEST(StretchLaw, IsSmoothAtTheKneeAndReachesItsStiffenedSlope) {
  const Real knee = kLaw.kneeStrain;
  for (Real joint : {knee, 2 * knee}) {
    const StretchResponse below = stretchResponse(kLaw, joint * (1 - 1e-12));
    const StretchResponse above = stretchResponse(kLaw, joint * (1 + 1e-12));
    // Across 2e-12 of relative strain: the energy moves by T·Δε, the tension by T'·Δε, the tangent
    // not at all (T is C¹).
    const Real step = 2e-12 * joint;
    EXPECT_NEAR(below.energyDensity, above.energyDensity, 2 * above.tension * step);
    EXPECT_NEAR(below.tension, above.tension, 2 * kLaw.stiffenedStiffness * step);
    EXPECT_NEAR(below.tangent, above.tangent, 1e-6 * kLaw.stiffenedStiffness);
  }
  EXPECT_EQ(stretchResponse(kLaw, 0.5 * knee).tangent, kLaw.stiffness);
  EXPECT_EQ(stretchResponse(kLaw, 3 * knee).tangent, kLaw.stiffenedStiffness);
  // Past 2 ε_k the tension is the line T = k₀ ε + (k₁ − k₀)(ε − 3ε_k/2).
  const Real strain = 0.1;
  EXPECT_NEAR(stretchResponse(kLaw, strain).tension,
              kLaw.stiffness * strain +
                  (kLaw.stiffenedStiffness - kLaw.stiffness) * (strain - 1.5 * knee),
              1e-9);
  // Compression is linear whatever the knee.
  EXPECT_EQ(stretchResponse(kLaw, -0.3).tension, kLaw.stiffness * -0.3);
}

TEST(StretchLaw, WithoutAKneeItIsLinear) {
  for (Real knee : {0.0, std::numeric_limits<Real>::infinity()}) {
    const StretchLaw law{260.0, knee, 24000.0};
    const StretchResponse response = stretchResponse(law, 0.3);
    EXPECT_EQ(response.tension, 260.0 * 0.3);
    EXPECT_EQ(response.tangent, 260.0);
    EXPECT_EQ(response.energyDensity, 0.5 * 260.0 * 0.3 * 0.3);
  }
}

// A triangle of 5 cm legs, stretched along warp by `strain`, with some out-of-plane motion.
struct StretchedTriangle {
  TriangleRest rest = makeTriangleRest({0, 1, 2}, Vec2(0, 0), Vec2(0.05, 0), Vec2(0, 0.05));
  Eigen::Matrix<Real, 9, 1> positions;
  Eigen::Matrix<Real, 9, 1> velocities;

  explicit StretchedTriangle(Real strain) {
    positions << 0, 0, 0, 0.05 * (1 + strain), 0.001, 0.002, 0.0005, 0.05, -0.001;
    velocities << 0.1, -0.2, 0.05, 0.0, 0.3, -0.1, 0.2, 0.1, 0.0;
  }

  ElementForces<3> forces(const Eigen::Matrix<Real, 9, 1>& x, const StretchLaw& law,
                          StiffnessMode mode) const {
    const StretchConditions conditions =
        stretchConditions(x.segment<3>(0), x.segment<3>(3), x.segment<3>(6), rest, 1.0, 1.0, true);
    ElementForces<3> out;
    accumulateStretchForces(conditions.warp, law, rest.area, 0.0, velocities, mode, true, out);
    return out;
  }
};

TEST(StretchLaw, BelowTheKneeATriangleFeelsTheLinearLawBitForBit) {
  const StretchedTriangle triangle(0.015);
  const StretchConditions conditions = stretchConditions(
      triangle.positions.segment<3>(0), triangle.positions.segment<3>(3),
      triangle.positions.segment<3>(6), triangle.rest, 1.0, 1.0, true);
  ASSERT_LT(conditions.warp.value / std::sqrt(triangle.rest.area), kLaw.kneeStrain);
  for (StiffnessMode mode : {StiffnessMode::Definite, StiffnessMode::Exact}) {
    ElementForces<3> biphasic, linear;
    accumulateStretchForces(conditions.warp, kLaw, triangle.rest.area, 0.5, triangle.velocities,
                            mode, true, biphasic);
    accumulateConditionForces(conditions.warp, kLaw.stiffness, 0.5, triangle.velocities, mode,
                              true, linear);
    EXPECT_EQ(biphasic.energy, linear.energy);
    EXPECT_TRUE(biphasic.force == linear.force);
    EXPECT_TRUE(biphasic.positionJacobian == linear.positionJacobian);
    EXPECT_TRUE(biphasic.velocityJacobian == linear.velocityJacobian);
  }
}

TEST(StretchLaw, AboveTheKneeForcesAndExactJacobianAreDerivatives) {
  for (Real strain : {0.03, 0.06}) {  // in the transition and on the stiff line
    const StretchedTriangle triangle(strain);
    const Real step = 1e-8;
    const ElementForces<3> at = triangle.forces(triangle.positions, kLaw, StiffnessMode::Exact);
    Eigen::Matrix<Real, 9, 9> jacobian;
    for (int j = 0; j < 9; ++j) {
      Eigen::Matrix<Real, 9, 1> plus = triangle.positions, minus = triangle.positions;
      plus[j] += step;
      minus[j] -= step;
      const ElementForces<3> up = triangle.forces(plus, kLaw, StiffnessMode::Exact);
      const ElementForces<3> down = triangle.forces(minus, kLaw, StiffnessMode::Exact);
      EXPECT_NEAR(at.force[j], -(up.energy - down.energy) / (2 * step),
                  1e-6 * at.force.norm())
          << "strain " << strain << " dof " << j;
      jacobian.col(j) = (up.force - down.force) / (2 * step);
    }
    EXPECT_LT((jacobian - at.positionJacobian).norm(), 1e-5 * at.positionJacobian.norm())
        << "strain " << strain;
    // The definite Jacobian is symmetric negative semi-definite.
    const ElementForces<3> definite =
        triangle.forces(triangle.positions, kLaw, StiffnessMode::Definite);
    EXPECT_LT((definite.positionJacobian - definite.positionJacobian.transpose()).norm(),
              1e-12 * definite.positionJacobian.norm());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, 9, 9>> eigen(definite.positionJacobian);
    EXPECT_LE(eigen.eigenvalues().maxCoeff(), 1e-9 * definite.positionJacobian.norm());
  }
}

TEST(StretchLaw, ValidationNamesTheFieldAndTheFix) {
  ClothMaterial material;
  EXPECT_EQ(stretchLawProblem(material), "");  // linear by default
  material.stretchKneeStrain = -0.1;
  EXPECT_THAT(stretchLawProblem(material), HasSubstr("material.stretchKneeStrain"));
  material.stretchKneeStrain = std::nan("");
  EXPECT_THAT(stretchLawProblem(material), HasSubstr("material.stretchKneeStrain"));
  material.stretchKneeStrain = 0.02;
  material.warpStiffenedStretchStiffness = 100;  // below the low-strain 260 N/m
  material.weftStiffenedStretchStiffness = 1000;
  EXPECT_THAT(stretchLawProblem(material), HasSubstr("material.warpStiffenedStretchStiffness"));
  EXPECT_THAT(stretchLawProblem(material), HasSubstr("at least material.warpStretchStiffness"));
  material.warpStiffenedStretchStiffness = 1000;
  material.weftStiffenedStretchStiffness = std::numeric_limits<Real>::infinity();
  EXPECT_THAT(stretchLawProblem(material), HasSubstr("material.weftStiffenedStretchStiffness"));
  material.weftStiffenedStretchStiffness = 1000;
  EXPECT_EQ(stretchLawProblem(material), "");
  for (std::string_view name : fabricPresetNames()) {
    EXPECT_EQ(stretchLawProblem(fabricPreset(name).value()), "") << name;
    EXPECT_EQ(stretchLawProblem(stiffeningFabricPreset(name).value()), "") << name;
  }
}

TEST(StretchLaw, StiffeningPresetsMeetTheirKesTensileTest) {
  // Kawabata's tensile test of cotton shirting (FabricPresets.cpp, [KES-T]): 500 gf/cm = 490.3 N/m
  // at EMT = 5 %, linearity LT = WT / (½ · 490.3 N/m · EMT) = 0.65; the low-strain slope kept
  // below the knee; the strain limit at EMT.
  const ClothMaterial linear = cottonFabric();
  const ClothMaterial cotton = stiffeningFabricPreset("cotton").value();
  const Real load = 500 * 9.80665e-3 / 0.01, emt = 0.05;
  const StretchLaw warp = warpStretchLaw(cotton);
  ASSERT_TRUE(warp.stiffens());
  EXPECT_EQ(warp.stiffness, linear.warpStretchStiffness);
  EXPECT_NEAR(stretchResponse(warp, emt).tension, load, 1e-9 * load);
  EXPECT_NEAR(stretchResponse(warp, emt).energyDensity / (0.5 * load * emt), 0.65, 1e-9);
  EXPECT_NEAR(stretchResponse(weftStretchLaw(cotton), emt).tension, load, 1e-9 * load);
  EXPECT_EQ(cotton.strainLimit, emt);
  // The rest is the linear preset's.
  EXPECT_EQ(cotton.arealDensity, linear.arealDensity);
  EXPECT_EQ(cotton.stretchDamping, linear.stretchDamping);
  EXPECT_EQ(cotton.shearStiffness, linear.shearStiffness);
  EXPECT_EQ(cotton.bendingStiffness, linear.bendingStiffness);
  EXPECT_EQ(linear.stretchKneeStrain, 0.0);
  EXPECT_FALSE(stiffeningFabricPreset("velvet").ok());
}

}  // namespace
}  // namespace weft
