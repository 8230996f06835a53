// Stress scene 11: mass ratios of 1 : 1000 between neighbouring vertices. A 0.6 m square pinned
// along one edge swings down from horizontal, its vertices alternately light and heavy in a
// checkerboard (every grid edge joins a light and a heavy vertex; the diagonals join equals), the
// total mass that of the cotton sheet (ClothSettings::vertexMasses).
#include "stress/StressSupport.h"

namespace weft::stress {
namespace {

TEST(StressMassRatio, CheckerboardOfOneToAThousandSwingsSafely) {
  constexpr Index kVertices = 13;
  auto model = horizontalSquare(kVertices, 0.6, 1.0);
  ClothSettings settings;
  settings.material = cottonFabric();  // the stress suite runs cotton, strain limiter on
  const Real average = model->totalMass(settings.material.arealDensity) / model->vertexCount();
  const Real light = 2 * average / 1001;
  for (Index row = 0; row < kVertices; ++row) {
    for (Index column = 0; column < kVertices; ++column) {
      settings.vertexMasses.push_back((row + column) % 2 ? light : 1000 * light);
    }
  }
  for (Index c = 0; c < kVertices; ++c) settings.pinnedVertices.push_back(c);
  World world;
  const ClothId cloth = world.createCloth(model, settings).value();
  StressMonitor monitor(world);
  monitor.watch(cloth, *model);
  for (int frame = 0; frame < 90; ++frame) {
    if (!monitor.afterFrame(world.step(1.0 / 60.0))) break;
  }
  EXPECT_LT(world.positions(cloth).value()[(kVertices - 1) * kVertices].y(), 0.6);
  monitor.expectPasses("mass_ratio_1_1000");
}

}  // namespace
}  // namespace weft::stress
