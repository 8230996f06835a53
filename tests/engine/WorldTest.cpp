// World: handles, validation that leaves the world unchanged, pins, health reporting and the
// state hash.
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace weft {
namespace {

using ::testing::HasSubstr;

std::shared_ptr<const ClothModel> smallGrid(Index columns = 11, Index rows = 9) {
  GridSettings grid;
  grid.columns = columns;
  grid.rows = rows;
  grid.width = 0.5;
  grid.height = 0.4;
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

ClothSettings pinnedTopRow(Index columns = 11, Index rows = 9) {
  ClothSettings settings;
  for (Index c = 0; c < columns; ++c) settings.pinnedVertices.push_back((rows - 1) * columns + c);
  return settings;
}

// The largest strain smallGrid() may reach hanging from its top row: twice the static strain
// under the top row, ρ_A g H / k (the weight of the 0.4 m below it), the most a load applied at
// once overshoots to.
Real hangingStrainBound() {
  const ClothMaterial material;
  return 2 * material.arealDensity * 9.81 * 0.4 / material.weftStretchStiffness;
}

TEST(World, HandlesGoStaleWhenDestroyed) {
  World world;
  const ClothId first = world.createCloth(smallGrid(), pinnedTopRow()).value();
  EXPECT_FALSE(first.isNull());
  EXPECT_TRUE(world.destroyCloth(first).ok());
  EXPECT_EQ(world.clothCount(), 0u);
  // The slot is reused with a new generation: the old handle must not reach the new cloth.
  const ClothId second = world.createCloth(smallGrid(), pinnedTopRow()).value();
  EXPECT_EQ(second.index, first.index);
  EXPECT_NE(second.generation, first.generation);
  EXPECT_THAT(world.positions(first).error().message, HasSubstr("destroyed cloth"));
  EXPECT_THAT(world.destroyCloth(first).error().message, HasSubstr("destroyed cloth"));
  EXPECT_THAT(world.positions(ClothId{}).error().message, HasSubstr("is null"));
  EXPECT_TRUE(world.positions(second).ok());
}

TEST(World, InvalidClothSettingsAreRefusedAndChangeNothing) {
  World world;
  (void)world.createCloth(smallGrid(), pinnedTopRow()).value();
  const std::uint64_t hash = world.stateHash();
  struct Case {
    void (*spoil)(ClothSettings&);
    const char* message;
  } cases[] = {
      {[](ClothSettings& s) { s.material.arealDensity = 0; }, "material.arealDensity = 0"},
      {[](ClothSettings& s) { s.material.arealDensity = -1; }, "greater than 0"},
      {[](ClothSettings& s) { s.material.shearStiffness = -5; }, "material.shearStiffness = -5"},
      {[](ClothSettings& s) { s.material.bendingStiffness = std::numeric_limits<Real>::quiet_NaN(); },
       "material.bendingStiffness"},
      {[](ClothSettings& s) { s.material.thickness = 0; }, "material.thickness"},
      {[](ClothSettings& s) { s.solver.cgTolerance = 0; }, "solver.cgTolerance"},
      {[](ClothSettings& s) { s.solver.maxSubsteps = 0; }, "solver.maxSubsteps"},
      {[](ClothSettings& s) { s.pinnedVertices.push_back(10'000); }, "pinned vertex 10000 does not exist"},
      {[](ClothSettings& s) { s.pinnedVertices.push_back(s.pinnedVertices[0]); }, "pinned twice"},
      {[](ClothSettings& s) { s.translation.x() = std::numeric_limits<Real>::infinity(); }, "translation"},
      {[](ClothSettings& s) { s.rotation(0, 0) = 2; }, "rotation"},
  };
  for (const Case& c : cases) {
    ClothSettings settings = pinnedTopRow();
    c.spoil(settings);
    Result<ClothId> id = world.createCloth(smallGrid(), settings);
    ASSERT_FALSE(id.ok());
    EXPECT_THAT(id.error().message, HasSubstr(c.message));
  }
  EXPECT_THAT(world.createCloth(nullptr, {}).error().message, HasSubstr("ClothModel is null"));
  EXPECT_EQ(world.clothCount(), 1u);
  EXPECT_EQ(world.stateHash(), hash);
}

TEST(World, BadFrameLengthIsRefusedWithoutChange) {
  World world;
  (void)world.createCloth(smallGrid(), pinnedTopRow()).value();
  const std::uint64_t hash = world.stateHash();
  for (Real dt : {0.0, -1.0 / 60, std::numeric_limits<Real>::quiet_NaN(),
                  std::numeric_limits<Real>::infinity()}) {
    EXPECT_EQ(world.step(dt), StepStatus::InvalidInput);
    EXPECT_EQ(world.stateHash(), hash);
    EXPECT_EQ(world.time(), 0.0);
  }
}

TEST(World, PinsFollowTheirTargetsExactly) {
  World world;
  const ClothSettings settings = pinnedTopRow();
  const ClothId cloth = world.createCloth(smallGrid(), settings).value();
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  for (Vec3& target : targets) target += Vec3(0.01, 0.02, -0.03);
  ASSERT_TRUE(world.setPinTargets(cloth, targets).ok());
  world.step(1.0 / 60.0);
  const std::span<const Vec3> x = world.positions(cloth).value();
  for (std::size_t k = 0; k < targets.size(); ++k) {
    EXPECT_EQ(x[settings.pinnedVertices[k]], targets[k]);
  }
  EXPECT_THAT(world.setPinTargets(cloth, std::vector<Vec3>(3)).error().message,
              HasSubstr("got 3 targets for 11 pinned vertices"));
  targets[2].x() = std::numeric_limits<Real>::quiet_NaN();
  EXPECT_THAT(world.setPinTargets(cloth, targets).error().message, HasSubstr("NaN"));
}

TEST(World, StateHashIsReproducibleAndSensitive) {
  World a, b;
  const ClothId clothA = a.createCloth(smallGrid(), pinnedTopRow()).value();
  (void)b.createCloth(smallGrid(), pinnedTopRow()).value();
  EXPECT_EQ(a.stateHash(), b.stateHash());
  for (int frame = 0; frame < 20; ++frame) {
    a.step(1.0 / 60.0);
    b.step(1.0 / 60.0);
    ASSERT_EQ(a.stateHash(), b.stateHash()) << "frame " << frame;
  }
  const std::uint64_t before = a.stateHash();
  std::vector<Vec3> targets = a.pinTargets(clothA).value();
  targets[0].z() += 1e-9;
  ASSERT_TRUE(a.setPinTargets(clothA, targets).ok());
  a.step(1.0 / 60.0);
  b.step(1.0 / 60.0);
  EXPECT_NE(a.stateHash(), b.stateHash());
  EXPECT_NE(a.stateHash(), before);
}

TEST(World, ExplicitMethodsPickStableSubstepsOrSaySoWhenCapped) {
  for (IntegratorKind kind : {IntegratorKind::SymplecticEuler, IntegratorKind::RungeKutta4,
                              IntegratorKind::Midpoint, IntegratorKind::ExplicitEuler}) {
    World world;
    ClothSettings settings = pinnedTopRow();
    settings.solver.integrator = kind;
    settings.solver.maxSubsteps = 100000;
    const ClothId cloth = world.createCloth(smallGrid(), settings).value();
    const Index substeps = world.plannedSubsteps(cloth, 1.0 / 60.0).value();
    EXPECT_GT(substeps, 1u) << integratorName(kind);
    if (substeps > 5000) continue;  // explicit Euler on stiff cloth: too slow for a unit test
    for (int frame = 0; frame < 10; ++frame) {
      ASSERT_EQ(world.step(1.0 / 60.0), StepStatus::Ok) << integratorName(kind);
    }
    EXPECT_LT(world.stats().maxStrain, hangingStrainBound()) << integratorName(kind);
  }
  // The same cloth with the substeps capped far below the stable count is reported unstable.
  World world;
  ClothSettings settings = pinnedTopRow();
  settings.solver.integrator = IntegratorKind::SymplecticEuler;
  settings.solver.maxSubsteps = 2;
  (void)world.createCloth(smallGrid(), settings).value();
  EXPECT_TRUE(hasFlag(world.step(1.0 / 60.0), StepStatus::Unstable));
}

TEST(World, DivergedExplicitStepsAreRolledBackNeverNaN) {
  World world;
  ClothSettings settings = pinnedTopRow();
  settings.solver.integrator = IntegratorKind::ExplicitEuler;
  settings.solver.substeps = 1;  // forced far beyond the stable step
  settings.material.stretchDamping = 0;
  settings.material.shearDamping = 0;
  const ClothId cloth = world.createCloth(smallGrid(), settings).value();
  bool rolledBack = false;
  for (int frame = 0; frame < 200; ++frame) {
    const StepStatus status = world.step(1.0 / 60.0);
    EXPECT_TRUE(hasFlag(status, StepStatus::Unstable));
    rolledBack |= hasFlag(status, StepStatus::RolledBack);
    for (const Vec3& x : world.positions(cloth).value()) ASSERT_TRUE(x.allFinite());
  }
  EXPECT_TRUE(rolledBack);
}

TEST(World, MassSpringClothHangsToo) {
  World world;
  ClothSettings settings = pinnedTopRow();
  settings.forceModel = ForceModel::MassSpring;
  const ClothId cloth = world.createCloth(smallGrid(), settings).value();
  for (int frame = 0; frame < 120; ++frame) ASSERT_EQ(world.step(1.0 / 60.0), StepStatus::Ok);
  // It hangs: the bottom row is below where it started, and strain stays small.
  EXPECT_LT(world.positions(cloth).value()[5].y(), 0.5);
  EXPECT_LT(world.stats().maxStrain, hangingStrainBound());
}

}  // namespace
}  // namespace weft
