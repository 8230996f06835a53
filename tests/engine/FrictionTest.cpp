// Coulomb friction: the pure kernel (static and kinetic); a whole cloth on an incline stepped by a
// World sticks below the friction angle and slides at g(sin θ − μ cos θ) above it (the projector's
// own test steps a single point); and the contact constraint of the solve on a grazing path.
#include "ContactTestSupport.h"
#include "contact/ContactDetector.h"

#include <weft/collision/Plane.h>
#include <weft/collision/Sphere.h>
#include <weft/engine/World.h>

#include <gtest/gtest.h>

#include <cmath>

namespace weft {
namespace {

TEST(CoulombFriction, SticksExactlyWithinTheCone) {
  const Vec3 tangential(0.3, 0, -0.4);  // 0.5 m/s
  // μ J = 0.5 and above: all of it is held.
  EXPECT_EQ(coulombFriction(tangential, 1.0, 0.5).norm(), 0.0);
  EXPECT_EQ(coulombFriction(tangential, 2.0, 0.5).norm(), 0.0);
  // A contact at rest stays at rest, even with no impulse.
  EXPECT_EQ(coulombFriction(Vec3::Zero(), 0.0, 0.3).norm(), 0.0);
}

TEST(CoulombFriction, SlidesWithTheKineticLossOutsideTheCone) {
  const Vec3 tangential(0.3, 0, -0.4);  // 0.5 m/s
  const Vec3 kept = coulombFriction(tangential, 0.5, 0.4);  // loses μ J = 0.2 m/s
  EXPECT_NEAR(kept.norm(), 0.3, 1e-15);
  EXPECT_NEAR(kept.normalized().dot(tangential.normalized()), 1.0, 1e-15);
  // No friction, or no impulse, keeps it all.
  EXPECT_EQ(coulombFriction(tangential, 1.0, 0.0), tangential);
  EXPECT_EQ(coulombFriction(tangential, 0.0, 0.3), tangential);
}

// A 30 cm cloth laid on a plane through the origin tilted by `degrees` about z (air drag off),
// stepped `frames` frames of 1/60 s; returns how far its centre moved.
Real clothSlideOnIncline(Real degrees, Real friction, int frames) {
  World world;
  const Real angle = degrees * M_PI / 180;
  const Vec3 normal(-std::sin(angle), std::cos(angle), 0);
  ColliderSettings surface;
  surface.friction = friction;
  (void)world.addCollider(Plane::create(normal).value(), surface).value();
  ClothSettings settings;
  settings.material.friction = friction;  // the pair takes the geometric mean: `friction`
  settings.material.airDrag = 0;
  settings.rotation = Eigen::AngleAxis<Real>(angle, Vec3::UnitZ()).toRotationMatrix();
  settings.translation = settings.material.thickness * normal;
  const ClothId cloth = world.createCloth(test::horizontalSquare(11, 0.3, 0.0), settings).value();
  const Vec3 start = world.positions(cloth).value()[60];
  test::StepHealth health;
  for (int frame = 0; frame < frames; ++frame) health(world.step(1.0 / 60));
  health.expectHealthy("cloth on an incline");
  return (world.positions(cloth).value()[60] - start).norm();
}

TEST(CoulombFriction, AClothBelowTheFrictionAngleStaysPutAndAboveItSlidesAtTheKineticRate) {
  // The whole step of a cloth: the solve's contact constraints, their impulses as friction's
  // bound, friction moving positions. Before (friction bounded by the step's velocity change,
  // acting on velocities), 3 s at μ 0.3: 12 cm at 10°, 4.2 m at 15° (tan 15° = 0.27 < μ) and
  // 12.3 m at 25° against Coulomb's 6.7 m.
  const int frames = 180;
  for (Real degrees : {10.0, 15.0}) {
    EXPECT_LT(clothSlideOnIncline(degrees, 0.3, frames), 1e-4) << degrees << "°";
  }
  // ½ a t² (1 + 1/N) with a = g (sin θ − μ cos θ), as for the point above (measured: 1 %).
  const Real angle = 25 * M_PI / 180, t = frames / 60.0;
  for (Real friction : {0.0, 0.3}) {
    const Real acceleration = 9.81 * (std::sin(angle) - friction * std::cos(angle));
    const Real coulomb = 0.5 * acceleration * t * t * (1 + 1.0 / frames);
    EXPECT_NEAR(clothSlideOnIncline(25, friction, frames), coulomb, 0.03 * coulomb) << "μ " << friction;
  }
}

TEST(ColliderConstraint, AGrazingPathOverACurvedBodyIsNotConstrained) {
  // A vertex on top of a 15 cm sphere that moves sideways by 6.7 cm in the step (4 m/s at
  // 1/60 s): relative to the body it slides off the top and ends clear. The tangent plane at the
  // point where its path first came near would put it inside, and the solve would then hold it
  // there against the cloth's tension.
  const Real h = 1.0 / 60, thickness = 0.003, radius = 0.15;
  RigidMotion start;
  start.linearVelocity = Vec3(0, 0, -4);
  const RigidMotion end = advanceMotion(start, h);
  ColliderFrame collider;
  collider.shape = Sphere::create(radius, end).value();
  collider.start = start;
  collider.end = end;
  // 2 cm behind the top, 0.3 mm above it: relative to the body its path passes over the top,
  // where it comes within half its start distance (the hit), and ends 7 mm clear.
  ContactSpace space;
  space.x = space.startX = {Vec3(0, radius + 0.0003, -0.02)};
  space.v = space.startV = {Vec3::Zero()};
  space.inverseMass = {1};
  space.owner = {0};
  space.owners = {ContactOwner{thickness, 0.3, false, false}};
  ContactDetector detector;
  DetectionCounts counts;
  std::vector<SolveConstraint> constraints;
  detector.constrain(space, std::span<const ColliderFrame>(&collider, 1), h, {}, constraints, counts);
  EXPECT_TRUE(constraints.empty());
  // Coming down into it (3 m/s: 3.6 cm inside at the end of the step) is constrained.
  space.startV = {Vec3(0, -3, 0)};
  detector.constrain(space, std::span<const ColliderFrame>(&collider, 1), h, {}, constraints, counts);
  ASSERT_EQ(constraints.size(), 1u);
  EXPECT_GT(constraints[0].normal.y(), 0.9);
}

}  // namespace
}  // namespace weft
