// The contact projector (engine/src/contact/ContactProjector.h) alone, on contact spaces built by
// hand: edges brought to their strain limit with momentum kept, pins immovable, collider contacts
// put on their thickness and followed back to their own side, pairs separated with the heavier
// side lifted, faces pushed off a core between their vertices, Coulomb friction at the position
// level, and all of them satisfied together.
#include "contact/ContactProjector.h"
#include "contact/ContactSpace.h"

#include <weft/collision/Proximity.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace weft {
namespace {

constexpr Real kStep = 1.0 / 60.0;
constexpr Real kThickness = 0.003;

// A contact space of `x` (at rest, started where it is), one owner, no topology yet.
ContactSpace spaceOf(const Vec3Array& x, const std::vector<Real>& inverseMasses,
                     Real friction = 0.3) {
  ContactSpace space;
  space.x = space.startX = x;
  space.v = space.startV = Vec3Array(x.size(), Vec3::Zero());
  space.inverseMass = inverseMasses;
  space.owner.assign(x.size(), 0);
  space.rest = x;
  space.owners = {ContactOwner{kThickness, friction, true, true}};
  return space;
}

// Adds an edge a–b of rest length `rest` limited to strain `limit`.
void addEdge(ContactSpace& space, Index a, Index b, Real rest, Real limit) {
  space.edges.push_back({a, b});
  space.restLengths.push_back(rest);
  space.longest.push_back((1 + limit) * rest);
}

Real strain(const ContactSpace& space, std::size_t e) {
  const Vec3 delta = space.x[space.edges[e][1]] - space.x[space.edges[e][0]];
  return delta.norm() / space.restLengths[e] - 1;
}

ProjectionReport project(ContactSpace& space, const ContactSet& set,
                         std::span<const ColliderFrame> colliders = {},
                         ProjectionSettings settings = {}) {
  ContactProjector projector;
  std::vector<FaceSupport> supports;
  return projector.project(space, set, colliders, kStep, settings, supports);
}

ColliderFrame stillCollider(const Shape& shape, Real friction = 0.3) {
  ColliderFrame collider;
  collider.shape = shape;
  collider.start = collider.end = motion(shape);
  collider.friction = friction;
  return collider;
}

Contact vertexContact(Index vertex, Index collider, Real friction, bool resting) {
  Contact contact;
  contact.kind = ContactKind::VertexCollider;
  contact.vertices[0] = vertex;
  contact.separation = kThickness;
  contact.friction = friction;
  contact.collider = collider;
  contact.resting = resting;
  return contact;
}

TEST(ContactProjector, AStretchedPairComesBackToTheLimitAndKeepsItsMomentum) {
  // 10 g and 30 g, 1.5 m apart on a 1 m edge limited to 10 %.
  ContactSpace space = spaceOf({Vec3(0, 0, 0), Vec3(1.5, 0, 0)}, {100, 100.0 / 3});
  addEdge(space, 0, 1, 1.0, 0.1);
  const ProjectionReport report = project(space, ContactSet{});
  EXPECT_NEAR(strain(space, 0), 0.1, 1e-12);
  EXPECT_GT(report.iterations, 0);
  EXPECT_EQ(report.edgesOverLimit, 0u);
  // Momentum: the light end moved three times as far; each move is a velocity change / h.
  const Vec3 momentum = 0.01 * space.v[0] + 0.03 * space.v[1];
  EXPECT_NEAR(momentum.norm(), 0, 1e-12);
  EXPECT_NEAR(space.x[0].x(), 0.3, 1e-12);
  EXPECT_NEAR(space.v[0].x(), 0.3 / kStep, 1e-9);
}

TEST(ContactProjector, AnEdgeWithinItsLimitIsLeftBitForBit) {
  const Vec3Array x{Vec3(0, 0, 0), Vec3(1.05, 0.01, 0), Vec3(1.05, 0.4, 0)};
  ContactSpace space = spaceOf(x, {1, 1, 1});
  addEdge(space, 0, 1, 1.0, 0.1);  // 5 % stretched
  addEdge(space, 1, 2, 1.0, 0.1);  // compressed
  const ProjectionReport report = project(space, ContactSet{});
  EXPECT_EQ(report.iterations, 0);
  EXPECT_EQ(space.x, x);
  EXPECT_EQ(space.v, Vec3Array(3, Vec3::Zero()));
}

TEST(ContactProjector, APinnedVertexDoesNotMoveAndTheChainComesToIt) {
  // A chain of 6 hanging from a pin, stretched to 1.5 times its rest length.
  Vec3Array x;
  std::vector<Real> inverseMasses;
  for (int i = 0; i < 6; ++i) {
    x.emplace_back(0, -0.15 * i, 0);
    inverseMasses.push_back(i == 0 ? 0 : 50);
  }
  ContactSpace space = spaceOf(x, inverseMasses);
  for (Index i = 1; i < 6; ++i) addEdge(space, i - 1, i, 0.1, 0.1);
  const ProjectionReport report = project(space, ContactSet{});
  EXPECT_EQ(space.x[0], x[0]);
  EXPECT_EQ(report.edgesOverLimit, 0u);
  for (std::size_t e = 0; e < space.edges.size(); ++e) {
    EXPECT_LE(strain(space, e), 0.1 + 1e-3) << "edge " << e;
  }
}

TEST(ContactProjector, AnEdgeBetweenTwoPinsIsLeftAloneAndNotCounted) {
  ContactSpace space = spaceOf({Vec3(0, 0, 0), Vec3(2, 0, 0)}, {0, 0});
  addEdge(space, 0, 1, 1.0, 0.1);
  const ProjectionReport report = project(space, ContactSet{});
  EXPECT_EQ(report.iterations, 0);
  EXPECT_EQ(report.edgesOverLimit, 0u);
  EXPECT_EQ(space.x[1], Vec3(2, 0, 0));
}

TEST(ContactProjector, TheIterationCapIsKeptAndWhatIsLeftIsReported) {
  Vec3Array x;
  std::vector<Real> inverseMasses;
  for (int i = 0; i < 40; ++i) {
    x.emplace_back(0.3 * i, 0, 0);
    inverseMasses.push_back(i == 0 ? 0 : 1);
  }
  ContactSpace space = spaceOf(x, inverseMasses);
  for (Index i = 1; i < 40; ++i) addEdge(space, i - 1, i, 0.1, 0.1);
  const ProjectionReport report = project(space, ContactSet{}, {}, {.maxIterations = 2});
  EXPECT_EQ(report.iterations, 2);
  EXPECT_GT(report.edgesOverLimit, 0u);
}

TEST(ContactProjector, PutsAVertexInsideASphereOnItsThicknessAndMakesTheMoveAVelocity) {
  const Shape ball = Sphere::create(0.1).value();
  const ColliderFrame collider = stillCollider(ball);
  // Started outside above the ball, ended 2 cm inside it.
  ContactSpace space = spaceOf({Vec3(0, 0.08, 0)}, {1});
  space.startX = {Vec3(0, 0.2, 0)};
  space.v = {Vec3(0, (0.08 - 0.2) / kStep, 0)};  // the substep's average velocity
  ContactSet set;
  set.contacts.push_back(vertexContact(0, 0, 0, false));
  set.firstPair = 1;
  project(space, set, std::span<const ColliderFrame>(&collider, 1));
  EXPECT_NEAR(space.x[0].y(), 0.1 + kThickness, 1e-12);
  // The push is a velocity change, then the approach is removed: it rests on the ball.
  EXPECT_NEAR(space.v[0].y(), 0, 1e-12);
}

TEST(ContactProjector, AVertexPulledAcrossAThinCapsuleGoesBackToTheSideItCameFrom) {
  // A rod of 1 cm radius along z; the vertex started 2 cm above its axis and an edge pulled it to
  // 0.5 cm below the axis: the nearest surface point is below, but it belongs above.
  RigidMotion pose;
  pose.pose.rotation = Quat::FromTwoVectors(Vec3::UnitY(), Vec3::UnitZ());
  const Shape rod = Capsule::create(0.01, 0.5, pose).value();
  const ColliderFrame collider = stillCollider(rod);
  ContactSpace space = spaceOf({Vec3(0, -0.005, 0)}, {1});
  space.startX = {Vec3(0, 0.02, 0)};
  ContactSet set;
  set.contacts.push_back(vertexContact(0, 0, 0, false));
  set.firstPair = 1;
  project(space, set, std::span<const ColliderFrame>(&collider, 1));
  EXPECT_GT(space.x[0].y(), 0.01);
  EXPECT_NEAR(queryPoint(rod, space.x[0]).distance, kThickness, 1e-9);
}

TEST(ContactProjector, SatisfiesTheEdgesAndTheCollidersTogether) {
  // An edge anchored at a pin, its free end pulled into a floor and far past the edge's limit:
  // the end must be on the floor's thickness and within the limit at once.
  const Shape floor = Plane::create(Vec3::UnitY()).value();
  const ColliderFrame collider = stillCollider(floor);
  ContactSpace space = spaceOf({Vec3(0, 0.05, 0), Vec3(0.3, -0.05, 0)}, {0, 1});
  space.startX = {Vec3(0, 0.05, 0), Vec3(0.1, 0.02, 0)};
  addEdge(space, 0, 1, 0.1, 0.1);
  ContactSet set;
  set.contacts.push_back(vertexContact(1, 0, 0, false));
  set.firstPair = 1;
  const ProjectionReport report = project(space, set, std::span<const ColliderFrame>(&collider, 1));
  EXPECT_EQ(report.edgesOverLimit, 0u);
  EXPECT_EQ(report.contactsViolated, 0u);
  EXPECT_LE(strain(space, 0), 0.1 + 1e-3);
  EXPECT_GE(space.x[1].y(), kThickness * (1 - 1e-2));
}

TEST(ContactProjector, AHeavyVertexOnALightStretchedTriangleIsLiftedWithIt) {
  // A 0.5 kg vertex resting 1 mm into a 1 g triangle pinned at two corners whose free corner is
  // stretched down: inside the pair both sides count as heavy as the weight, so the edges lift the
  // weight with the triangle instead of pulling the triangle through it.
  const Vec3Array x{Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.05, -0.2, 0.05),
                    Vec3(0.05, -0.102, 0.017)};
  ContactSpace space = spaceOf(x, {0, 0, 1000, 2});
  addEdge(space, 0, 2, 0.1, 0.1);
  addEdge(space, 1, 2, 0.1, 0.1);
  Contact pair;
  pair.kind = ContactKind::VertexFace;
  pair.vertices = {3, 0, 1, 2};
  const Vec3 normal = (x[1] - x[0]).cross(x[2] - x[0]).normalized();
  pair.normal = normal.y() > 0 ? normal : Vec3(-normal);
  const TriangleClosestPoint closest = closestPointOnTriangle(x[3], x[0], x[1], x[2]);
  pair.weights = {1, -closest.barycentric[0], -closest.barycentric[1], -closest.barycentric[2]};
  pair.separation = kThickness;
  ContactSet set;
  set.contacts.push_back(pair);
  const ProjectionReport report = project(space, set);
  EXPECT_EQ(report.edgesOverLimit, 0u);
  EXPECT_EQ(report.contactsViolated, 0u);
  for (std::size_t e = 0; e < 2; ++e) EXPECT_LE(strain(space, e), 0.1 + 1e-3);
  Vec3 gap = Vec3::Zero();
  for (int k = 0; k < 4; ++k) gap += pair.weights[k] * space.x[pair.vertices[k]];
  EXPECT_GE(pair.normal.dot(gap), kThickness * (1 - 1e-2));
  EXPECT_GT(space.x[3].y(), x[3].y());  // the weight went up with the triangle
}

TEST(ContactProjector, APairAlreadyApartIsLeftAlone) {
  const Vec3Array x{Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0, 0, 0.1), Vec3(0.02, 0.01, 0.02)};
  ContactSpace space = spaceOf(x, {1, 1, 1, 1});
  Contact pair;
  pair.kind = ContactKind::VertexFace;
  pair.vertices = {3, 0, 1, 2};
  pair.normal = Vec3::UnitY();
  pair.weights = {1, -0.6, -0.2, -0.2};
  pair.separation = kThickness;
  ContactSet set;
  set.contacts.push_back(pair);
  const ProjectionReport report = project(space, set);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_EQ(space.x, x);
}

// A point resting on a plane tilted by `angle` about z, stepped `steps` times by symplectic Euler
// under gravity, each step projected: returns its displacement along the plane.
Real slideOnIncline(Real angle, Real friction, int steps) {
  const Vec3 normal(-std::sin(angle), std::cos(angle), 0);
  const Shape plane = Plane::create(normal).value();
  const ColliderFrame collider = stillCollider(plane, friction);
  ContactSpace space = spaceOf({Vec3(kThickness * normal)}, {1}, friction);
  ContactSet set;
  set.contacts.push_back(vertexContact(0, 0, friction, true));
  set.firstPair = 1;
  ContactProjector projector;
  std::vector<FaceSupport> supports;
  const Vec3 gravity(0, -9.81, 0);
  for (int step = 0; step < steps; ++step) {
    space.startX = space.x;
    space.v[0] += kStep * gravity;
    space.x[0] += kStep * space.v[0];
    projector.project(space, set, std::span<const ColliderFrame>(&collider, 1), kStep, {}, supports);
  }
  const Vec3 moved = space.x[0] - kThickness * normal;
  return (moved - moved.dot(normal) * normal).norm();
}

TEST(ContactProjector, FrictionHoldsAPointBelowTheFrictionAngleAndSlidesItAboveAtTheKineticRate) {
  constexpr Real kFriction = 0.3;  // friction angle 16.7°
  constexpr int kSteps = 180;
  EXPECT_LT(slideOnIncline(10 * M_PI / 180, kFriction, kSteps), 1e-12);
  EXPECT_LT(slideOnIncline(15 * M_PI / 180, kFriction, kSteps), 1e-12);
  // Above it: g (sin θ − μ cos θ) t²/2 for the discrete steps (Σ k h² a = a h² n(n+1)/2).
  const Real angle = 25 * M_PI / 180;
  const Real acceleration = 9.81 * (std::sin(angle) - kFriction * std::cos(angle));
  const Real expected = 0.5 * acceleration * kStep * kStep * kSteps * (kSteps + 1);
  EXPECT_NEAR(slideOnIncline(angle, kFriction, kSteps), expected, 1e-3 * expected);
}

TEST(ContactProjector, PushesAFaceOffASphereBetweenItsVerticesAndPinsStay) {
  // A 5 cm ball 2 cm into the middle of a level face whose vertices are all far outside it; one
  // corner pinned.
  const Shape ball = Sphere::create(0.05).value();
  const ColliderFrame collider = stillCollider(ball);
  const Vec3Array x{Vec3(-0.1, 0.03, -0.1), Vec3(0.2, 0.03, -0.1), Vec3(-0.1, 0.03, 0.2)};
  ContactSpace space = spaceOf(x, {0, 1, 1});
  space.startX = {x[0] + Vec3(0, 0.1, 0), x[1] + Vec3(0, 0.1, 0), x[2] + Vec3(0, 0.1, 0)};
  ContactSet set;
  set.cores.push_back(makeCore(Vec3::Zero(), Vec3::Zero(), 0.05 - kThickness));
  Contact face;
  face.kind = ContactKind::FaceCollider;
  face.vertices = {0, 1, 2, kInvalidIndex};
  face.normal = Vec3::UnitY();  // the core-to-face direction at the start
  face.separation = 0.05 - kThickness;
  face.collider = 0;
  face.core = 0;
  set.contacts.push_back(face);
  set.firstPair = 1;
  std::vector<FaceSupport> supports;
  ContactProjector projector;
  projector.project(space, set, std::span<const ColliderFrame>(&collider, 1), kStep, {}, supports);
  EXPECT_EQ(space.x[0], x[0]);
  const Real gap = closestPointOnTriangle(Vec3::Zero(), space.x[0], space.x[1], space.x[2]).distance;
  EXPECT_NEAR(gap, 0.05 - kThickness, 1e-6);
  // The face rests on the ball: a support for the next solve, and no velocity into the ball.
  ASSERT_FALSE(supports.empty());
  EXPECT_GT(supports[0].normal.y(), 0.9);
  for (int k = 1; k < 3; ++k) EXPECT_GE(space.v[k].y(), -1e-9) << "vertex " << k;
}

TEST(ContactProjector, AFaceThatCrossedTheCoreGoesBackToTheSideItCameFrom) {
  // The face started 1 cm above the centre of a 5 cm ball and ended 1 cm below it, its vertices
  // outside the ball throughout: its own normal at the end points down, through the ball.
  const Shape ball = Sphere::create(0.05).value();
  const ColliderFrame collider = stillCollider(ball);
  const Vec3Array x{Vec3(-0.1, -0.01, -0.1), Vec3(0.2, -0.01, -0.1), Vec3(-0.1, -0.01, 0.2)};
  ContactSpace space = spaceOf(x, {1, 1, 1});
  ContactSet set;
  set.cores.push_back(makeCore(Vec3::Zero(), Vec3::Zero(), 0.05));
  Contact face;
  face.kind = ContactKind::FaceCollider;
  face.vertices = {0, 1, 2, kInvalidIndex};
  face.normal = Vec3::UnitY();
  face.separation = 0.05;
  face.collider = 0;
  face.core = 0;
  set.contacts.push_back(face);
  set.firstPair = 1;
  project(space, set, std::span<const ColliderFrame>(&collider, 1));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(space.x[k].y(), 0.05, 1e-9) << "vertex " << k;
}

}  // namespace
}  // namespace weft
