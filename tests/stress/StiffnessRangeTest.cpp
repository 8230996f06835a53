// Stress scene 2: stiffness × 1 … × 10⁴. A 0.6 m square of cotton, pinned along one edge, starts
// horizontal and swings down under gravity for 1.5 s at 60 frames/s (implicit Euler, default
// solver settings, then again with the multicolour Gauss–Seidel preconditioner). Stretch, shear and bending stiffness are multiplied together; damping stays,
// so the stiff cloths are also the least damped relative to their stiffness.
#include "stress/StressSupport.h"

#include <cmath>
#include <string>

namespace weft::stress {
namespace {

/// Runs the swing for 90 frames with `preconditioner` and checks the four conditions (the solver
/// cap as a known failure when capIsKnownFailure).
void swing(Real factor, PreconditionerKind preconditioner, bool capIsKnownFailure) {
  constexpr Index kVertices = 13;
  World world;
  auto model = horizontalSquare(kVertices, 0.6, 1.0);
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  settings.material.warpStretchStiffness *= factor;
  settings.material.weftStretchStiffness *= factor;
  settings.material.shearStiffness *= factor;
  settings.material.bendingStiffness *= factor;
  settings.solver.preconditioner = preconditioner;
  for (Index c = 0; c < kVertices; ++c) settings.pinnedVertices.push_back(c);  // the row at z = +0.3
  const ClothId cloth = world.createCloth(model, settings).value();
  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  for (int frame = 0; frame < 90; ++frame) {
    if (!monitor.afterFrame(world.step(1.0 / 60.0))) break;
  }
  // It swung down: the free edge is well below the pinned one.
  EXPECT_LT(world.positions(cloth).value()[(kVertices - 1) * kVertices].y(), 0.6);
  const std::string name = std::string(preconditioner == PreconditionerKind::BlockJacobi
                                           ? "stiffness_x"
                                           : "gauss_seidel_stiffness_x") +
                           std::to_string(std::lround(factor));
  if (capIsKnownFailure) {
    monitor.expectPasses(name, kCottonStrainLimit,
                         {{StressMonitor::Condition::SolverCap,
                           "block-Jacobi PCG needs more than 200 iterations at stiffness x 10^3 "
                           "(SolverSettings::preconditioner = MulticolorGaussSeidel passes)"}});
  } else {
    monitor.expectPasses(name);
  }
}

class StressStiffness : public ::testing::TestWithParam<Real> {};

// Default solver settings (block-Jacobi PCG). Known engine failure, measured: × 10³ hits the
// 200-iteration cap in 12 of 90 frames (13 %), × 10⁴ in none (the most in a frame: 198); with the
// dihedral bending (before the isometric default) × 10⁴ hit it in about 9 %. The fix exists but is
// opt-in: see the Gauss–Seidel test below and SolverSettings::preconditioner for why it is not
// the default yet.
TEST_P(StressStiffness, SwingingSheetPassesTheFourConditions) {
  swing(GetParam(), PreconditionerKind::BlockJacobi, GetParam() == 1e3);
}

// The same scene with the multicolour Gauss–Seidel preconditioner: all four conditions, the cap
// included, asserted at every stiffness. Measured: no capped frame; at most 97 iterations in a
// frame at × 10³ and 87 at × 10⁴ (bench/SolverCompare.cpp; same tolerance and stopping norm).
TEST_P(StressStiffness, GaussSeidelSwingingSheetPassesTheFourConditions) {
  swing(GetParam(), PreconditionerKind::MulticolorGaussSeidel, false);
}

INSTANTIATE_TEST_SUITE_P(Factors, StressStiffness, ::testing::Values(1.0, 10.0, 100.0, 1e3, 1e4),
                         [](const ::testing::TestParamInfo<Real>& info) {
                           // append(): GCC 12 warns falsely (-Wrestrict) on "x" + string.
                           return std::string("x").append(std::to_string(std::lround(info.param)));
                         });

}  // namespace
}  // namespace weft::stress
