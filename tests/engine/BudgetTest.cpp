// Frame budget: a budgeted step plans from measured costs, reports misses, records the plan it
// ran, and a replay of the recorded plans gives the same bits. The planner itself is tested on
// synthetic measurements (no timing in tests).
#include "ContactTestSupport.h"
#include "FrameCostModel.h"

#include <weft/engine/World.h>
#include <weft/scenes/Curtain.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace weft {
namespace {

CurtainScene curtain(Real cgTolerance = SolverSettings{}.cgTolerance) {
  CurtainSettings settings;
  settings.threadCount = 1;
  settings.solver.cgTolerance = cgTolerance;
  return CurtainScene::create(settings).value();
}

// The curtain's material: cotton, strain limit 0.10.
const Real kStrainLimit = CurtainSettings{}.material.strainLimit;

TEST(Budget, ARecordedPlanReplaysBitForBit) {
  // A budget no machine meets: every plan after the first frame is relaxed, and every frame is
  // reported missed.
  StepBudget budget;
  budget.milliseconds = 0.01;
  CurtainScene budgeted = curtain();
  std::vector<StepPlan> plans;
  std::vector<std::uint64_t> hashes;
  int relaxed = 0;
  test::StepHealth health;
  for (int frame = 0; frame < 40; ++frame) {
    const StepStatus status = health(budgeted.stepFrame(budget));
    EXPECT_TRUE(hasFlag(status, StepStatus::BudgetMissed)) << "frame " << frame + 1;
    const StepStats& stats = budgeted.world().stats();
    EXPECT_EQ(stats.budgetMs, budget.milliseconds);
    plans.push_back(stats.plan);
    hashes.push_back(budgeted.world().stateHash());
    if (!(stats.plan == StepPlan{})) {
      ++relaxed;
      EXPECT_GE(stats.plan.cgMaxIterations, budget.fewestCgIterations);
      EXPECT_LE(stats.plan.cgTolerance, budget.loosestCgTolerance);
      EXPECT_GE(stats.plan.cgTolerance, 1e-3);
      // A relaxed plan loosens the solve, not the strain limit (cotton's 0.10) + 0.01.
      EXPECT_LE(stats.maxStrain, kStrainLimit + 0.01) << "frame " << frame + 1;
    }
  }
  EXPECT_GE(relaxed, 39);  // all but the first, which had nothing to plan from
  health.expectHealthy("budgeted curtain");
  CurtainScene replay = curtain();
  for (std::size_t frame = 0; frame < plans.size(); ++frame) {
    const StepStatus status = replay.stepFrame(plans[frame]);
    EXPECT_FALSE(hasFlag(status, StepStatus::BudgetMissed));  // a replay has no budget
    ASSERT_EQ(replay.world().stateHash(), hashes[frame]) << "frame " << frame + 1;
    EXPECT_EQ(replay.world().stats().plan, plans[frame]);
  }
}

TEST(Budget, AGenerousBudgetChangesNothing) {
  StepBudget budget;
  budget.milliseconds = 1e6;
  CurtainScene budgeted = curtain(), plain = curtain();
  for (int frame = 0; frame < 20; ++frame) {
    const StepStatus status = budgeted.stepFrame(budget);
    plain.stepFrame();
    EXPECT_FALSE(hasFlag(status, StepStatus::BudgetMissed));
    EXPECT_EQ(budgeted.world().stats().plan, StepPlan{});
    ASSERT_EQ(budgeted.world().stateHash(), plain.world().stateHash()) << "frame " << frame + 1;
  }
}

TEST(Budget, ARelaxedPlanTradesResidualNotSafety) {
  // The same frames with the loosest plan the defaults allow: a larger residual, but contacts
  // still resolved and the cloth within its strain limit + 0.01, as in the exact run. The
  // default tolerance is already the loosest a plan may use (StepBudget::loosestCgTolerance), so
  // the exact run solves to 1e-3 (the same stopping test) and the plan also caps the iterations.
  CurtainScene exact = curtain(1e-3), loose = curtain();
  StepPlan plan;
  StepBudget limits;
  plan.cgTolerance = limits.loosestCgTolerance;
  plan.cgMaxIterations = limits.fewestCgIterations;
  Real exactResidual = 0, looseResidual = 0, exactStrain = 0, looseStrain = 0;
  test::StepHealth exactHealth, looseHealth;
  for (int frame = 0; frame < 90; ++frame) {  // into the sphere's push
    exactHealth(exact.stepFrame());
    looseHealth(loose.stepFrame(plan));
    exactResidual = std::max(exactResidual, exact.world().stats().cgResidual);
    looseResidual = std::max(looseResidual, loose.world().stats().cgResidual);
    exactStrain = std::max(exactStrain, exact.world().stats().maxStrain);
    looseStrain = std::max(looseStrain, loose.world().stats().maxStrain);
  }
  std::printf("[budget] max strain %.4f with the loosest plan, %.4f exact\n", looseStrain, exactStrain);
  EXPECT_GT(looseResidual, exactResidual);
  EXPECT_LE(exactStrain, kStrainLimit + 0.01);
  EXPECT_LE(looseStrain, kStrainLimit + 0.01);
  exactHealth.expectHealthy("exact curtain");
  looseHealth.expectHealthy("relaxed curtain");
  EXPECT_GT(loose.world().stats().contacts, 0u);
  // Nothing inside the sphere: the response always projects onto the surface plus thickness.
  const Vec3 centre = motion(*loose.world().collider(loose.sphere()).value()).pose.position;
  for (const Vec3& x : loose.world().positions(loose.cloth()).value()) {
    EXPECT_GE((x - centre).norm(), CurtainScene::kSphereRadius);
  }
}

TEST(Budget, InvalidBudgetsAndPlansAreRefusedWithoutChange) {
  CurtainScene scene = curtain();
  scene.stepFrame();
  const std::uint64_t hash = scene.world().stateHash();
  const Real time = scene.world().time();
  StepBudget nan;
  nan.milliseconds = std::numeric_limits<Real>::quiet_NaN();
  StepBudget negative;
  negative.milliseconds = -1;
  StepBudget badTolerance;
  badTolerance.milliseconds = 2;
  badTolerance.loosestCgTolerance = 0;
  StepBudget badSmoothing;
  badSmoothing.milliseconds = 2;
  badSmoothing.costSmoothing = 0;
  for (const StepBudget& budget : {nan, negative, badTolerance, badSmoothing}) {
    EXPECT_EQ(scene.world().step(CurtainScene::kFrameDt, budget), StepStatus::InvalidInput);
  }
  StepPlan badPlan;
  badPlan.cgTolerance = -1;
  EXPECT_EQ(scene.world().step(CurtainScene::kFrameDt, badPlan), StepStatus::InvalidInput);
  badPlan.cgTolerance = 0;
  badPlan.cgMaxIterations = -3;
  EXPECT_EQ(scene.world().step(CurtainScene::kFrameDt, badPlan), StepStatus::InvalidInput);
  badPlan.cgMaxIterations = 0;
  badPlan.substeps = 1000000;  // beyond SolverSettings::maxSubsteps
  EXPECT_EQ(scene.world().step(CurtainScene::kFrameDt, badPlan), StepStatus::InvalidInput);
  EXPECT_EQ(scene.world().stateHash(), hash);
  EXPECT_EQ(scene.world().time(), time);
}

TEST(FrameCostModel, PlansFromMeasurementsWithinTheLimits) {
  FrameCostModel model;
  PlanDefaults defaults;  // 1 substep, 1e-3, 200 iterations
  StepBudget budget;
  budget.milliseconds = 1.75;
  budget.headroom = 1.0;
  budget.loosestCgTolerance = 0.1;  // wider limits than the defaults, to see every stage
  budget.fewestCgIterations = 4;
  EXPECT_EQ(model.plan(budget, defaults), StepPlan{});  // nothing measured yet: own settings
  // A measured frame: 4 ms, of which 3 ms in 30 PCG iterations (0.1 ms each) at 1e-3.
  StepStats frame;
  frame.stepMs = 4;
  frame.solveMs = 3;
  frame.cgIterations = 30;
  frame.linearSolves = 1;
  model.record(frame, 1, 1e-3, 1.0);
  EXPECT_DOUBLE_EQ(model.msPerSubstep(), 1.0);
  EXPECT_DOUBLE_EQ(model.msPerIteration(), 0.1);
  EXPECT_DOUBLE_EQ(model.iterationsPerDecade(), 10.0);
  EXPECT_NEAR(model.predictMs(1, 1e-3, 200), 4.0, 1e-12);
  // 1.75 ms leaves 0.75 ms for iterations: 7 of them; tolerance 1e-1 (10 iterations, 2 ms) is
  // not enough on its own.
  const StepPlan plan = model.plan(budget, defaults);
  EXPECT_EQ(plan.substeps, 1u);
  EXPECT_DOUBLE_EQ(plan.cgTolerance, 0.1);
  EXPECT_EQ(plan.cgMaxIterations, 7);
  EXPECT_LE(model.predictMs(plan.substeps, plan.cgTolerance, plan.cgMaxIterations),
            budget.headroom * budget.milliseconds + 1e-12);
  // 3.5 ms: a looser tolerance alone suffices (1e-2: 20 iterations, 3 ms).
  budget.milliseconds = 3.5;
  const StepPlan looser = model.plan(budget, defaults);
  EXPECT_DOUBLE_EQ(looser.cgTolerance, 1e-2);
  EXPECT_EQ(looser.cgMaxIterations, 200);
  // A generous budget keeps the cloths' own settings.
  budget.milliseconds = 10;
  EXPECT_EQ(model.plan(budget, defaults), StepPlan{});
  // Never below the floor of iterations; substeps drop for implicit cloths only.
  budget.milliseconds = 0.1;
  defaults.substeps = 4;
  const StepPlan tight = model.plan(budget, defaults);
  EXPECT_EQ(tight.cgMaxIterations, budget.fewestCgIterations);
  EXPECT_DOUBLE_EQ(tight.cgTolerance, budget.loosestCgTolerance);
  EXPECT_EQ(tight.substeps, 1u);
  defaults.allImplicit = false;
  EXPECT_EQ(model.plan(budget, defaults).substeps, 4u);
}

}  // namespace
}  // namespace weft
