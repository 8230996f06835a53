// Stress scene 2: stiffness × 1 … × 10⁴. A 0.6 m square of cotton, pinned along one edge, starts
// horizontal and swings down under gravity for 1.5 s at 60 frames/s (implicit Euler, default
// solver settings). Stretch, shear and bending stiffness are multiplied together; damping stays,
// so the stiff cloths are also the least damped relative to their stiffness.
#include "stress/StressSupport.h"

#include <cmath>
#include <string>

namespace weft::stress {
namespace {

class StressStiffness : public ::testing::TestWithParam<Real> {};

TEST_P(StressStiffness, SwingingSheetPassesTheFourConditions) {
  const Real factor = GetParam();
  constexpr Index kVertices = 13;
  World world;
  auto model = horizontalSquare(kVertices, 0.6, 1.0);
  ClothSettings settings;
  settings.material.warpStretchStiffness *= factor;
  settings.material.weftStretchStiffness *= factor;
  settings.material.shearStiffness *= factor;
  settings.material.bendingStiffness *= factor;
  for (Index c = 0; c < kVertices; ++c) settings.pinnedVertices.push_back(c);  // the row at z = +0.3
  const ClothId cloth = world.createCloth(model, settings).value();
  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  for (int frame = 0; frame < 90; ++frame) {
    if (!monitor.afterFrame(world.step(1.0 / 60.0))) break;
  }
  // It swung down: the free edge is well below the pinned one.
  EXPECT_LT(world.positions(cloth).value()[(kVertices - 1) * kVertices].y(), 0.6);
  // Known engine failure, measured: from × 10³ the block-Jacobi PCG can hit its 200-iteration
  // cap at the default tolerance. With dihedral bending × 10⁴ hit it in about 9 % of frames;
  // with the isometric bending (default since, 2-ring coupling) × 10³ hits it in 13 % and × 10⁴
  // in none. A stronger preconditioner is the fix; the mark says so instead of hiding it.
  if (factor >= 1e3) {
    monitor.expectPasses("stiffness_x" + std::to_string(std::lround(factor)), kCottonStrainLimit,
                         {{StressMonitor::Condition::SolverCap,
                           "block-Jacobi PCG needs more than 200 iterations at stiffness x 10^3 and above"}});
  } else {
    monitor.expectPasses("stiffness_x" + std::to_string(std::lround(factor)));
  }
}

INSTANTIATE_TEST_SUITE_P(Factors, StressStiffness, ::testing::Values(1.0, 10.0, 100.0, 1e3, 1e4),
                         [](const ::testing::TestParamInfo<Real>& info) {
                           // append(): GCC 12 warns falsely (-Wrestrict) on "x" + string.
                           return std::string("x").append(std::to_string(std::lround(info.param)));
                         });

}  // namespace
}  // namespace weft::stress
