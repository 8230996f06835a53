// SelfCollision resolving the same step twice (Cloth::limitStrainInContact's rounds): the second
// resolve() reuses the proximity contacts and the swept certificate of the first
// (ContactResolver::setBroadPhaseIsPure). Its results must be bit for bit those of a resolver
// that sees the step for the first time.
#include "SelfCollision.h"

#include <weft/engine/ClothModel.h>
#include <weft/threading/TaskSystem.h>

#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <vector>

namespace weft {
namespace {

struct FoldedStep {
  std::shared_ptr<const ClothModel> model;
  Vec3Array start, end;
};

// A strip folded over itself: the upper half 2 mm above the lower one on one side (inside the
// 3 mm thickness: proximity contacts) and 8 mm on the other, and over the step the upper half
// falls to 5 mm below the lower one (swept impacts where proximity did not stop it).
FoldedStep foldedStep() {
  GridSettings grid;
  grid.columns = 12;
  grid.rows = 6;
  grid.width = 0.3;
  grid.height = 0.15;
  grid.origin = Vec3::Zero();
  FoldedStep step;
  step.model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  const Real fold = 0.5 * grid.width;
  for (const Vec3& rest : step.model->restPositions()) {
    Vec3 start = rest, end = rest;
    if (rest.x() > fold) {
      const Real gap = rest.y() < 0.06 ? 0.002 : 0.008;
      start = Vec3(2 * fold - rest.x(), rest.y(), gap);
      end = Vec3(start.x(), start.y(), -0.005);
    }
    step.start.push_back(start);
    step.end.push_back(end);
  }
  return step;
}

bool sameBits(const Vec3Array& a, const Vec3Array& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

void expectSameReport(const SelfCollisionReport& a, const SelfCollisionReport& b) {
  EXPECT_EQ(a.proximityContacts, b.proximityContacts);
  EXPECT_EQ(a.impacts, b.impacts);
  EXPECT_EQ(a.impactZones, b.impactZones);
  EXPECT_EQ(a.frozenVertices, b.frozenVertices);
}

void checkSecondResolveMatchesAFreshOne(TaskSystem* tasks) {
  const FoldedStep step = foldedStep();
  const Real h = 1.0 / 60, thickness = 0.003, friction = 0.3;
  const std::vector<Real> inverseMasses(step.start.size(), 1.0);

  SelfCollision reused(*step.model, tasks);
  Vec3Array x = step.end, v(step.start.size());
  for (std::size_t i = 0; i < x.size(); ++i) v[i] = (x[i] - step.start[i]) / h;
  const SelfCollisionReport first = reused.resolve(step.start, h, thickness, friction, inverseMasses, x, v);
  ASSERT_GT(first.proximityContacts, 0);  // the test means something only with both stages
  ASSERT_GT(first.impacts, 0);

  // What the strain limiter does between rounds: moves some vertices, not all. Here the upper
  // half's last rows back through the lower layer.
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (step.start[i].z() > 0.005 && step.start[i].y() > 0.09) {
      x[i].z() = -0.03;
      v[i] = (x[i] - step.start[i]) / h;
    }
  }
  Vec3Array freshX = x, freshV = v;

  const SelfCollisionReport second =
      reused.resolve(step.start, h, thickness, friction, inverseMasses, x, v);
  SelfCollision fresh(*step.model, tasks);
  const SelfCollisionReport expected =
      fresh.resolve(step.start, h, thickness, friction, inverseMasses, freshX, freshV);
  EXPECT_GT(expected.impacts, 0);
  expectSameReport(second, expected);
  EXPECT_TRUE(sameBits(x, freshX));
  EXPECT_TRUE(sameBits(v, freshV));

  // A third resolve of what the second left: nothing moved, still the same as a fresh resolver.
  Vec3Array againX = x, againV = v;
  const SelfCollisionReport third =
      reused.resolve(step.start, h, thickness, friction, inverseMasses, x, v);
  SelfCollision freshAgain(*step.model, tasks);
  expectSameReport(third, freshAgain.resolve(step.start, h, thickness, friction, inverseMasses,
                                             againX, againV));
  EXPECT_TRUE(sameBits(x, againX));
  EXPECT_TRUE(sameBits(v, againV));

  // A new step start: nothing is carried over (the start moved by 1 µm).
  Vec3Array start = step.start;
  for (Vec3& point : start) point.z() += 1e-6;
  Vec3Array newX = step.end, newV(start.size());
  for (std::size_t i = 0; i < newX.size(); ++i) newV[i] = (newX[i] - start[i]) / h;
  Vec3Array newFreshX = newX, newFreshV = newV;
  const SelfCollisionReport moved = reused.resolve(start, h, thickness, friction, inverseMasses, newX, newV);
  SelfCollision freshMoved(*step.model, tasks);
  expectSameReport(moved, freshMoved.resolve(start, h, thickness, friction, inverseMasses,
                                             newFreshX, newFreshV));
  EXPECT_TRUE(sameBits(newX, newFreshX));
  EXPECT_TRUE(sameBits(newV, newFreshV));
}

TEST(SelfCollisionReuse, ASecondResolveOfTheSameStepMatchesAFreshResolverBitForBit) {
  checkSecondResolveMatchesAFreshOne(nullptr);
}

TEST(SelfCollisionReuse, TheSameOnTwoThreads) {
  TaskSystem tasks(TaskSystemSettings{2});
  checkSecondResolveMatchesAFreshOne(&tasks);
}

}  // namespace
}  // namespace weft
