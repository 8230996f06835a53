// Analytic colliders: signed distances and normals inside and outside, poses, kinematic surface
// velocity, bounds, and validation messages.
#include <weft/collision/Shape.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace weft {
namespace {

using ::testing::HasSubstr;

constexpr Real kPi = 3.14159265358979323846;
const Real kNaN = std::numeric_limits<Real>::quiet_NaN();

RigidMotion at(const Vec3& position, const Quat& rotation = Quat::Identity()) {
  RigidMotion motion;
  motion.pose.position = position;
  motion.pose.rotation = rotation;
  return motion;
}

void expectVecNear(const Vec3& actual, const Vec3& expected, Real tolerance) {
  EXPECT_LT((actual - expected).norm(), tolerance) << "actual " << actual.transpose()
                                                   << ", expected " << expected.transpose();
}

// Every contact: point + distance · normal gives back the query point.
void expectConsistent(const ShapeContact& contact, const Vec3& query) {
  expectVecNear(contact.point + contact.distance * contact.normal, query, 1e-12);
  EXPECT_NEAR(contact.normal.norm(), 1, 1e-12);
}

TEST(Plane, DistanceAndNormalOnBothSides) {
  Result<Plane> floor = Plane::create(Vec3(0, 2, 0));  // normalised
  ASSERT_TRUE(floor.ok()) << floor.error().message;
  ShapeContact above = floor->queryPoint(Vec3(3, 0.5, -1));
  EXPECT_NEAR(above.distance, 0.5, 1e-15);
  expectVecNear(above.normal, Vec3(0, 1, 0), 1e-15);
  expectVecNear(above.point, Vec3(3, 0, -1), 1e-15);
  ShapeContact below = floor->queryPoint(Vec3(3, -0.25, -1));
  EXPECT_NEAR(below.distance, -0.25, 1e-15);
  expectConsistent(below, Vec3(3, -0.25, -1));
  // The floor's solid side is bounded above by y = 0 and unbounded elsewhere.
  EXPECT_EQ(floor->bounds().max.y(), 0);
  EXPECT_TRUE(std::isinf(floor->bounds().min.y()));
}

TEST(Plane, PoseTiltsAndMovesIt) {
  // Rotated 90° about z: the local +y normal becomes world −x; through (1, 0, 0).
  const Quat quarterTurn(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ()));
  Result<Plane> wall = Plane::create(Vec3::UnitY(), at(Vec3(1, 0, 0), quarterTurn));
  ASSERT_TRUE(wall.ok());
  expectVecNear(wall->normal(), Vec3(-1, 0, 0), 1e-15);
  const ShapeContact contact = wall->queryPoint(Vec3(0.25, 7, 3));
  EXPECT_NEAR(contact.distance, 0.75, 1e-14);  // the quarter turn is rounded
  expectConsistent(contact, Vec3(0.25, 7, 3));
}

TEST(Sphere, DistanceInsideOutsideAndAtTheCentre) {
  Result<Sphere> ball = Sphere::create(0.25, at(Vec3(0.3, 1.1, -0.5)));
  ASSERT_TRUE(ball.ok());
  const Vec3 outside = Vec3(0.3, 1.1, -0.5) + Vec3(0.6, 0, 0.8);  // 1 m from the centre
  ShapeContact contact = ball->queryPoint(outside);
  EXPECT_NEAR(contact.distance, 0.75, 1e-14);
  expectVecNear(contact.normal, Vec3(0.6, 0, 0.8), 1e-14);
  expectConsistent(contact, outside);
  const Vec3 inside = Vec3(0.3, 1.1, -0.5) + Vec3(0, -0.1, 0);
  contact = ball->queryPoint(inside);
  EXPECT_NEAR(contact.distance, -0.15, 1e-14);
  expectVecNear(contact.normal, Vec3(0, -1, 0), 1e-14);
  // At the centre: a defined normal, depth = radius.
  contact = ball->queryPoint(Vec3(0.3, 1.1, -0.5));
  EXPECT_NEAR(contact.distance, -0.25, 1e-15);
  EXPECT_NEAR(contact.normal.norm(), 1, 1e-15);
  expectVecNear(ball->bounds().min, Vec3(0.05, 0.85, -0.75), 1e-15);
  expectVecNear(ball->bounds().max, Vec3(0.55, 1.35, -0.25), 1e-15);
}

TEST(Sphere, RotatingSphereSurfaceVelocity) {
  // Spinning at 2 rad/s about +y and moving at 1 m/s along +z: the surface point at +x moves at
  // v + ω × r = (0, 0, 1) + (0, 2, 0) × (0.5, 0, 0) = (0, 0, 1) + (0, 0, −1) = 0.
  RigidMotion motion = at(Vec3(0, 1, 0));
  motion.linearVelocity = Vec3(0, 0, 1);
  motion.angularVelocity = Vec3(0, 2, 0);
  Result<Sphere> ball = Sphere::create(0.5, motion);
  ASSERT_TRUE(ball.ok());
  expectVecNear(ball->queryPoint(Vec3(3, 1, 0)).velocity, Vec3(0, 0, 0), 1e-15);
  // At −x the spin adds: (0, 0, 2). At the pole (on the axis) only the translation: (0, 0, 1).
  expectVecNear(ball->queryPoint(Vec3(-3, 1, 0)).velocity, Vec3(0, 0, 2), 1e-15);
  expectVecNear(ball->queryPoint(Vec3(0, 5, 0)).velocity, Vec3(0, 0, 1), 1e-15);
}

TEST(Capsule, DistanceToTheCoreSegment) {
  // Axis along world x after a −90° turn about z (local +y → world +x).
  const Quat turn(Eigen::AngleAxis<Real>(-kPi / 2, Vec3::UnitZ()));
  Result<Capsule> capsule = Capsule::create(0.1, 0.5, at(Vec3(0, 1, 0), turn));
  ASSERT_TRUE(capsule.ok());
  // Beside the middle of the side.
  ShapeContact contact = capsule->queryPoint(Vec3(0.2, 1.3, 0));
  EXPECT_NEAR(contact.distance, 0.2, 1e-14);
  expectVecNear(contact.normal, Vec3(0, 1, 0), 1e-14);
  // Beyond the end cap at x = 0.5.
  contact = capsule->queryPoint(Vec3(0.9, 1, 0));
  EXPECT_NEAR(contact.distance, 0.3, 1e-14);
  expectVecNear(contact.normal, Vec3(1, 0, 0), 1e-14);
  // Inside, near the side.
  contact = capsule->queryPoint(Vec3(-0.3, 1, 0.06));
  EXPECT_NEAR(contact.distance, -0.04, 1e-14);
  expectConsistent(contact, Vec3(-0.3, 1, 0.06));
  const Aabb box = capsule->bounds();
  expectVecNear(box.min, Vec3(-0.6, 0.9, -0.1), 1e-14);
  expectVecNear(box.max, Vec3(0.6, 1.1, 0.1), 1e-14);
}

TEST(Box, OutsideFaceEdgeCornerAndInside) {
  Result<Box> box = Box::create(Vec3(1, 2, 3), at(Vec3(10, 0, 0)));
  ASSERT_TRUE(box.ok());
  // Face region.
  ShapeContact contact = box->queryPoint(Vec3(12, 0.5, 0.5));
  EXPECT_NEAR(contact.distance, 1, 1e-14);
  expectVecNear(contact.normal, Vec3(1, 0, 0), 1e-14);
  // Corner region.
  contact = box->queryPoint(Vec3(12, 3, 4));
  EXPECT_NEAR(contact.distance, std::sqrt(3.0), 1e-14);
  expectVecNear(contact.point, Vec3(11, 2, 3), 1e-14);
  // Inside: nearest face is +y (depth 0.5) rather than x (depth 0.9) or z (depth 2).
  contact = box->queryPoint(Vec3(10.1, 1.5, 1));
  EXPECT_NEAR(contact.distance, -0.5, 1e-14);
  expectVecNear(contact.normal, Vec3(0, 1, 0), 1e-14);
  expectConsistent(contact, Vec3(10.1, 1.5, 1));
  // At the centre: ties nothing, smallest half extent (x) wins.
  contact = box->queryPoint(Vec3(10, 0, 0));
  EXPECT_NEAR(contact.distance, -1, 1e-14);
  EXPECT_NEAR(std::abs(contact.normal.x()), 1, 1e-14);
}

TEST(Box, RotatedBoxDistancesAndBounds) {
  // A cube of half extent 1 turned 45° about z: its corner points along +x at √2.
  const Quat turn(Eigen::AngleAxis<Real>(kPi / 4, Vec3::UnitZ()));
  Result<Box> box = Box::create(Vec3(1, 1, 1), at(Vec3::Zero(), turn));
  ASSERT_TRUE(box.ok());
  ShapeContact contact = box->queryPoint(Vec3(2, 0, 0));
  EXPECT_NEAR(contact.distance, 2 - std::sqrt(2.0), 1e-14);  // nearest to the vertical edge
  expectVecNear(contact.normal, Vec3(1, 0, 0), 1e-14);
  contact = box->queryPoint(Vec3(0, 0, 0.5));
  EXPECT_NEAR(contact.distance, -0.5, 1e-14);
  expectVecNear(contact.normal, Vec3(0, 0, 1), 1e-14);
  expectVecNear(box->bounds().max, Vec3(std::sqrt(2.0), std::sqrt(2.0), 1), 1e-14);
}

TEST(Shape, VariantDispatchAndSetMotion) {
  Shape shape = Sphere::create(0.5).value();
  EXPECT_NEAR(queryPoint(shape, Vec3(0, 2, 0)).distance, 1.5, 1e-15);
  RigidMotion moved = at(Vec3(0, 1, 0));
  moved.linearVelocity = Vec3(1, 0, 0);
  ASSERT_TRUE(setMotion(shape, moved).ok());
  EXPECT_NEAR(queryPoint(shape, Vec3(0, 2, 0)).distance, 0.5, 1e-15);
  EXPECT_EQ(motion(shape).linearVelocity, Vec3(1, 0, 0));
  EXPECT_EQ(bounds(shape).max, Vec3(0.5, 1.5, 0.5));
  // A bad motion leaves the shape where it was.
  RigidMotion bad = moved;
  bad.pose.position.x() = kNaN;
  EXPECT_FALSE(setMotion(shape, bad).ok());
  EXPECT_EQ(motion(shape).pose.position, Vec3(0, 1, 0));
}

TEST(ShapeValidation, ReadableErrors) {
  Result<Sphere> sphere = Sphere::create(-1);
  ASSERT_FALSE(sphere.ok());
  EXPECT_THAT(sphere.error().message, HasSubstr("Sphere: radius is -1 m"));
  EXPECT_FALSE(Sphere::create(0).ok());
  EXPECT_FALSE(Sphere::create(kNaN).ok());

  Result<Capsule> capsule = Capsule::create(0.1, -0.5);
  ASSERT_FALSE(capsule.ok());
  EXPECT_THAT(capsule.error().message, HasSubstr("half length is -0.5"));
  EXPECT_FALSE(Capsule::create(0, 1).ok());

  Result<Box> box = Box::create(Vec3(1, 0, 1));
  ASSERT_FALSE(box.ok());
  EXPECT_THAT(box.error().message, HasSubstr("Box: half extents (1, 0, 1)"));

  Result<Plane> plane = Plane::create(Vec3::Zero());
  ASSERT_FALSE(plane.ok());
  EXPECT_THAT(plane.error().message, HasSubstr("cannot be normalised"));

  RigidMotion nanPose = at(Vec3(kNaN, 0, 0));
  sphere = Sphere::create(1, nanPose);
  ASSERT_FALSE(sphere.ok());
  EXPECT_THAT(sphere.error().message, HasSubstr("pose position (nan, 0, 0) is not finite"));

  RigidMotion scaledRotation = at(Vec3::Zero(), Quat(2, 0, 0, 0));
  box = Box::create(Vec3::Ones(), scaledRotation);
  ASSERT_FALSE(box.ok());
  EXPECT_THAT(box.error().message, HasSubstr("rotation has norm 2"));

  RigidMotion spinning = at(Vec3::Zero());
  spinning.angularVelocity.z() = std::numeric_limits<Real>::infinity();
  capsule = Capsule::create(1, 1, spinning);
  ASSERT_FALSE(capsule.ok());
  EXPECT_THAT(capsule.error().message, HasSubstr("angular velocity"));
}

}  // namespace
}  // namespace weft
