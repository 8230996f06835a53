// Coulomb friction of the collider response: the pure kernel (static and kinetic), and a point
// on an incline stepped as a cloth vertex is (symplectic Euler, then the response pass): below
// the friction angle it sticks, and does not creep when friction's velocity change moves the
// position too (ColliderResponse::resolve's positionStep; velocity-level friction alone lets it
// creep h² a_t per step, the cause of the drape sliding off the sphere in ColliderTest); above
// the friction angle it slides at g(sin θ − μ cos θ). The same for a whole cloth stepped by a
// World, and the contact constraint of the solve on a grazing path.
#include "ColliderResponse.h"
#include "ContactTestSupport.h"

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

// A point on a plane through the origin tilted by `angle` about z, stepped `steps` times by
// symplectic Euler under gravity and then the response pass, as a cloth's step does. Returns
// its displacement along the plane.
Real slideOnIncline(Real angle, Real friction, int steps, Real h, bool movePositions) {
  const Vec3 normal(-std::sin(angle), std::cos(angle), 0);
  Shape plane = Plane::create(normal).value();
  const ColliderFrame collider{&plane, RigidMotion{}, RigidMotion{}, friction};
  const Real thickness = 0.003;
  const Vec3 gravity(0, -9.81, 0);
  Vec3Array x{Vec3(thickness * normal)}, v{Vec3::Zero()}, xStart, vStart;
  const std::vector<char> pinned{0};
  const ColliderResponse response;
  for (int step = 0; step < steps; ++step) {
    xStart = x;
    vStart = v;
    v[0] += h * gravity;
    x[0] += h * v[0];
    const ColliderResponseReport report = response.resolve(
        std::span<const ColliderFrame>(&collider, 1), xStart, vStart, thickness, pinned, x, v,
        nullptr, /*friction=*/true, /*positionStep=*/movePositions ? h : 0);
    EXPECT_EQ(report.contacts, 1) << "step " << step;
  }
  const Vec3 moved = x[0] - thickness * normal;
  return (moved - moved.dot(normal) * normal).norm();
}

TEST(CoulombFriction, APointBelowTheFrictionAngleStaysPut) {
  // tan 10° = 0.18 < μ = 0.3: static friction holds it for 5 s of 1/240 s steps.
  const Real angle = 10 * M_PI / 180;
  EXPECT_LT(slideOnIncline(angle, 0.3, 1200, 1.0 / 240, /*movePositions=*/true), 1e-12);
  // Friction on the velocity alone (what Cloth's step does today) lets it creep h² g sin θ a
  // step although it sticks: 5 s × (1/240 s) × 1.70 m/s² = 3.5 cm.
  const Real crept = slideOnIncline(angle, 0.3, 1200, 1.0 / 240, /*movePositions=*/false);
  EXPECT_NEAR(crept, 5.0 / 240 * 9.81 * std::sin(angle), 0.001);
}

TEST(CoulombFriction, APointAboveTheFrictionAngleSlidesAtTheKineticRate) {
  // tan 30° = 0.58 > μ = 0.3: v gains h a a step, a = g (sin θ − μ cos θ) = 2.36 m/s². With
  // x = x₀ + h v after friction it goes h² a N(N + 1)/2 in N steps: ½ a t² (1 + 1/N), 1.18 m in
  // 1 s.
  const Real angle = 30 * M_PI / 180, friction = 0.3, h = 1.0 / 240, g = 9.81;
  const int steps = 240;
  const Real acceleration = g * (std::sin(angle) - friction * std::cos(angle));
  EXPECT_NEAR(slideOnIncline(angle, friction, steps, h, true),
              0.5 * acceleration * (1 + 1.0 / steps), 1e-9);
  // Frictionless: a = g sin θ.
  EXPECT_NEAR(slideOnIncline(angle, 0.0, steps, h, true),
              0.5 * g * std::sin(angle) * (1 + 1.0 / steps), 1e-9);
  // With velocity-level friction alone each step moves with the velocity before friction,
  // h (v + h g sin θ): ½ a t² (1 − 1/N) + h t g sin θ, 1.4 cm further in this second.
  EXPECT_NEAR(slideOnIncline(angle, friction, steps, h, false),
              0.5 * acceleration * (1 - 1.0 / steps) + h * g * std::sin(angle), 1e-9);
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
  // point where its path first came near put it inside, and the solve then held it there
  // against the cloth's tension (an impulse of 36 m/s in the withdrawing-sphere scene of
  // ColliderSlidingTest, where the end was 1.7 cm clear and the plane said 0.5 mm inside).
  const Real h = 1.0 / 60, thickness = 0.003, radius = 0.15;
  RigidMotion start;
  start.linearVelocity = Vec3(0, 0, -4);
  const RigidMotion end = advanceMotion(start, h);
  Shape sphere = Sphere::create(radius, end).value();
  const ColliderFrame collider{&sphere, start, end, 0.3};
  // 2 cm behind the top, 0.3 mm above it: relative to the body its path passes over the top,
  // where it comes within half its start distance (1.6 mm; the hit), and ends 7 mm clear.
  const Vec3Array x{Vec3(0, radius + 0.0003, -0.02)}, v{Vec3::Zero()};
  const std::vector<char> pinned{0};
  VertexFilter filter;
  filter.resize(1);
  ColliderResponse response;
  EXPECT_EQ(response.constrain(std::span<const ColliderFrame>(&collider, 1), x, v, h, thickness,
                               pinned, filter), 0);
  // Coming down into it (3 m/s: 3.6 cm inside at the end of the step) is constrained.
  const Vec3Array falling{Vec3(0, -3, 0)};
  ASSERT_EQ(response.constrain(std::span<const ColliderFrame>(&collider, 1), x, falling, h,
                               thickness, pinned, filter), 1);
  EXPECT_EQ(filter.kind(0), ConstraintKind::OneDirection);
}

}  // namespace
}  // namespace weft
