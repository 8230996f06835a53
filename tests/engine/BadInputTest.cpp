// Bad input at every public entry point (issue 9) and at the extremes (issue 22): each case is
// refused with a message that names the input and the fix, and a world it was handed to is left
// exactly as it was (state hash, time, cloth count, pin targets and collider poses compared
// before and after); an extreme input that is legal runs a finite simulation whose status flags
// say what happened. Files are read only when they are regular and small enough, and sizes are
// checked against the index range and the available memory before anything is allocated.
#include <weft/engine/FabricPresets.h>
#include <weft/engine/InputFile.h>
#include <weft/engine/World.h>

#include "HeapCounter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>

namespace weft {
namespace {

using ::testing::HasSubstr;

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
constexpr Real kInf = std::numeric_limits<Real>::infinity();
constexpr Index kColumns = 6, kRows = 5;

std::shared_ptr<const ClothModel> smallGrid() {
  GridSettings grid;
  grid.columns = kColumns;
  grid.rows = kRows;
  grid.width = 0.5;
  grid.height = 0.4;
  return std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
}

ClothSettings pinnedTopRow() {
  ClothSettings settings;
  for (Index c = 0; c < kColumns; ++c) settings.pinnedVertices.push_back((kRows - 1) * kColumns + c);
  return settings;
}

// A world with one stepped cloth and a sphere, and a snapshot of everything a bad call could
// change.
class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    cloth = world.createCloth(smallGrid(), pinnedTopRow()).value();
    sphere = world.addCollider(Sphere::create(0.1, RigidMotion{{Vec3(0, 0, -1)}}).value()).value();
    for (int frame = 0; frame < 3; ++frame) ASSERT_EQ(world.step(1.0 / 60.0), StepStatus::Ok);
    snapshot();
  }

  void snapshot() {
    hash = world.stateHash();
    time = world.time();
    clothCount = world.clothCount();
    targets = world.pinTargets(cloth).value();
    spherePosition = motion(*world.collider(sphere).value()).pose.position;
  }

  // The world is exactly as the snapshot.
  void expectUnchanged(const char* what) {
    EXPECT_EQ(world.stateHash(), hash) << what;
    EXPECT_EQ(world.time(), time) << what;
    EXPECT_EQ(world.clothCount(), clothCount) << what;
    EXPECT_EQ(world.pinTargets(cloth).value(), targets) << what;
    EXPECT_EQ(motion(*world.collider(sphere).value()).pose.position, spherePosition) << what;
  }

  // `status` failed with a message holding every one of `names`, and the world is unchanged.
  template <typename R>
  void expectRefused(const R& result, std::initializer_list<const char*> names, const char* what) {
    ASSERT_FALSE(result.ok()) << what;
    for (const char* name : names) EXPECT_THAT(result.error().message, HasSubstr(name)) << what;
    expectUnchanged(what);
  }

  World world;
  ClothId cloth;
  ColliderId sphere;
  std::uint64_t hash = 0;
  Real time = 0;
  Index clothCount = 0;
  std::vector<Vec3> targets;
  Vec3 spherePosition;
};

// ------------------------------------------------------------------------------ createCloth

TEST_F(BadInput, NullModel) {
  expectRefused(world.createCloth(nullptr, ClothSettings{}), {"ClothModel is null"}, "null model");
}

TEST_F(BadInput, NonPositiveOrNonFiniteDensity) {
  for (Real density : {0.0, -0.15, kNaN, kInf}) {
    ClothSettings settings;
    settings.material.arealDensity = density;
    expectRefused(world.createCloth(smallGrid(), settings), {"material.arealDensity"}, "density");
  }
}

TEST_F(BadInput, NonPositiveOrNonFiniteThickness) {
  for (Real thickness : {0.0, -0.003, kNaN, kInf}) {
    ClothSettings settings;
    settings.material.thickness = thickness;
    expectRefused(world.createCloth(smallGrid(), settings), {"material.thickness"}, "thickness");
  }
}

TEST_F(BadInput, NegativeOrNonFiniteStiffnessAndDamping) {
  struct Field {
    Real ClothMaterial::*member;
    const char* name;
  } fields[] = {
      {&ClothMaterial::warpStretchStiffness, "material.warpStretchStiffness"},
      {&ClothMaterial::weftStretchStiffness, "material.weftStretchStiffness"},
      {&ClothMaterial::shearStiffness, "material.shearStiffness"},
      {&ClothMaterial::bendingStiffness, "material.bendingStiffness"},
      {&ClothMaterial::stretchDamping, "material.stretchDamping"},
      {&ClothMaterial::shearDamping, "material.shearDamping"},
      {&ClothMaterial::bendingDamping, "material.bendingDamping"},
      {&ClothMaterial::airDrag, "material.airDrag"},
      {&ClothMaterial::friction, "material.friction"},
      {&ClothMaterial::warpRestScale, "material.warpRestScale"},
      {&ClothMaterial::weftRestScale, "material.weftRestScale"},
  };
  for (const Field& field : fields) {
    for (Real value : {-1.0, kNaN, kInf}) {
      ClothSettings settings;
      settings.material.*field.member = value;
      expectRefused(world.createCloth(smallGrid(), settings), {field.name}, field.name);
    }
  }
}

TEST_F(BadInput, NegativeOrNonFiniteSpringStiffness) {
  struct Field {
    Real MassSpringMaterial::*member;
    const char* name;
  } fields[] = {
      {&MassSpringMaterial::structuralStiffness, "springs.structuralStiffness"},
      {&MassSpringMaterial::shearStiffness, "springs.shearStiffness"},
      {&MassSpringMaterial::flexionStiffness, "springs.flexionStiffness"},
      {&MassSpringMaterial::structuralDamping, "springs.structuralDamping"},
  };
  for (const Field& field : fields) {
    for (Real value : {-260.0, kNaN}) {
      ClothSettings settings;
      settings.forceModel = ForceModel::MassSpring;
      settings.springs.*field.member = value;
      expectRefused(world.createCloth(smallGrid(), settings), {field.name}, field.name);
    }
  }
}

TEST_F(BadInput, BadSolverSettings) {
  auto refuse = [&](void (*spoil)(SolverSettings&), const char* name) {
    ClothSettings settings;
    spoil(settings.solver);
    expectRefused(world.createCloth(smallGrid(), settings), {name}, name);
  };
  refuse([](SolverSettings& s) { s.maxImplicitStep = 0; }, "solver.maxImplicitStep");
  refuse([](SolverSettings& s) { s.maxImplicitStep = kNaN; }, "solver.maxImplicitStep");
  refuse([](SolverSettings& s) { s.cgTolerance = -1e-3; }, "solver.cgTolerance");
  refuse([](SolverSettings& s) { s.cgMaxIterations = 0; }, "solver.cgMaxIterations");
  // The contact-aware tightening: a relative residual in [0, 1), thresholds above 0.
  refuse([](SolverSettings& s) { s.tightCgTolerance = -1e-3; }, "solver.tightCgTolerance");
  refuse([](SolverSettings& s) { s.tightCgTolerance = 1; }, "solver.tightCgTolerance");
  refuse([](SolverSettings& s) { s.tightCgTolerance = kNaN; }, "solver.tightCgTolerance");
  refuse([](SolverSettings& s) { s.tightSelfContactDensity = 0; }, "solver.tightSelfContactDensity");
  refuse([](SolverSettings& s) { s.tightSelfContactDensity = kNaN; }, "solver.tightSelfContactDensity");
  refuse([](SolverSettings& s) { s.tightPinTravel = -1; }, "solver.tightPinTravel");
  refuse([](SolverSettings& s) { s.tightPinTravel = kNaN; }, "solver.tightPinTravel");
  refuse([](SolverSettings& s) { s.newtonIterations = -1; }, "solver.newtonIterations");
  refuse([](SolverSettings& s) { s.selfContactStiffness = -1; }, "solver.selfContactStiffness");
  refuse([](SolverSettings& s) { s.selfContactStiffness = kNaN; }, "solver.selfContactStiffness");
  refuse([](SolverSettings& s) { s.maxSubsteps = 0; }, "solver.maxSubsteps");
  refuse([](SolverSettings& s) { s.integrator = IntegratorKind(17); }, "solver.integrator");
}

TEST_F(BadInput, UnknownForceModel) {
  ClothSettings settings;
  settings.forceModel = ForceModel(9);
  expectRefused(world.createCloth(smallGrid(), settings), {"forceModel"}, "force model");
}

TEST_F(BadInput, NonFinitePoseOrImproperRotation) {
  ClothSettings settings;
  settings.translation = Vec3(0, kNaN, 0);
  expectRefused(world.createCloth(smallGrid(), settings), {"translation"}, "NaN translation");
  settings = ClothSettings{};
  settings.rotation(1, 1) = kInf;
  expectRefused(world.createCloth(smallGrid(), settings), {"rotation"}, "infinite rotation");
  settings = ClothSettings{};
  settings.rotation = -Mat3::Identity();  // orthonormal but a reflection
  expectRefused(world.createCloth(smallGrid(), settings), {"rotation"}, "reflection");
  settings = ClothSettings{};
  settings.rotation *= 2;
  expectRefused(world.createCloth(smallGrid(), settings), {"rotation"}, "scaled rotation");
}

TEST_F(BadInput, PinsToMissingOrRepeatedVertices) {
  ClothSettings settings;
  settings.pinnedVertices = {0, kColumns * kRows};
  expectRefused(world.createCloth(smallGrid(), settings), {"pinned vertex 30 does not exist"},
                "pin past the end");
  settings.pinnedVertices = {0, kInvalidIndex};
  expectRefused(world.createCloth(smallGrid(), settings), {"does not exist"}, "invalid index pin");
  settings.pinnedVertices = {3, 1, 3};
  expectRefused(world.createCloth(smallGrid(), settings), {"vertex 3 is pinned twice"}, "repeated pin");
}

TEST_F(BadInput, BadVertexMasses) {
  const std::shared_ptr<const ClothModel> model = smallGrid();
  ClothSettings settings;
  settings.vertexMasses.assign(model->vertexCount() - 1, 0.01);
  expectRefused(world.createCloth(model, settings), {"vertexMasses has 29 entries", "30 vertices"},
                "wrong count");
  for (Real mass : {0.0, -0.01, kNaN, kInf}) {
    settings.vertexMasses.assign(model->vertexCount(), 0.01);
    settings.vertexMasses[7] = mass;
    expectRefused(world.createCloth(model, settings), {"vertexMasses[7]"}, "bad mass");
  }
}

TEST(BadInputWorld, NonFiniteGravityOrWindRefusesEveryCloth) {
  for (const Vec3& vector : {Vec3(0, kNaN, 0), Vec3(kInf, 0, 0)}) {
    WorldSettings gravity;
    gravity.gravity = vector;
    World first(gravity);
    EXPECT_THAT(first.createCloth(smallGrid(), {}).error().message, HasSubstr("gravity or wind"));
    EXPECT_EQ(first.clothCount(), 0u);
    WorldSettings wind;
    wind.wind = vector;
    World second(wind);
    EXPECT_THAT(second.createCloth(smallGrid(), {}).error().message, HasSubstr("gravity or wind"));
    EXPECT_EQ(second.clothCount(), 0u);
  }
}

// ------------------------------------------------------------------------- handles

TEST_F(BadInput, NullAndStaleClothHandlesAreRefusedByEveryFunction) {
  const ClothId doomed = world.createCloth(smallGrid(), pinnedTopRow()).value();
  ASSERT_TRUE(world.destroyCloth(doomed).ok());
  snapshot();
  const std::vector<Vec3> positions(kColumns * kRows, Vec3::Zero());
  const std::vector<Vec3> pins(kColumns, Vec3::Zero());
  for (const ClothId& id : {ClothId{}, doomed, ClothId{99, 1}, ClothId{cloth.index, cloth.generation + 1}}) {
    const char* kind = id.isNull() ? "is null" : "destroyed cloth";
    expectRefused(world.destroyCloth(id), {"destroyCloth", kind}, "destroyCloth");
    expectRefused(world.setPinTargets(id, pins), {"setPinTargets", kind}, "setPinTargets");
    expectRefused(world.setState(id, positions, positions), {"setState", kind}, "setState");
    expectRefused(world.pinTargets(id), {"pinTargets", kind}, "pinTargets");
    expectRefused(world.renderView(id), {"renderView", kind}, "renderView");
    expectRefused(world.positions(id), {"positions", kind}, "positions");
    expectRefused(world.velocities(id), {"velocities", kind}, "velocities");
    expectRefused(world.plannedSubsteps(id, 1.0 / 60), {"plannedSubsteps", kind}, "plannedSubsteps");
  }
}

TEST_F(BadInput, NullAndStaleColliderHandlesAreRefusedByEveryFunction) {
  const ColliderId doomed = world.addCollider(Sphere::create(0.2).value()).value();
  ASSERT_TRUE(world.destroyCollider(doomed).ok());
  snapshot();
  for (const ColliderId& id : {ColliderId{}, doomed, ColliderId{42, 1}}) {
    const char* kind = id.isNull() ? "is null" : "destroyed collider";
    expectRefused(world.destroyCollider(id), {"destroyCollider", kind}, "destroyCollider");
    expectRefused(world.setColliderMotion(id, RigidMotion{}), {"setColliderMotion", kind},
                  "setColliderMotion");
    expectRefused(world.collider(id), {"collider", kind}, "collider");
  }
}

// ------------------------------------------------------------------------- pins and state

TEST_F(BadInput, PinTargetsOfTheWrongCount) {
  expectRefused(world.setPinTargets(cloth, std::vector<Vec3>(kColumns - 1)),
                {"got 5 targets for 6 pinned vertices"}, "too few");
  expectRefused(world.setPinTargets(cloth, std::vector<Vec3>(kColumns + 3)),
                {"got 9 targets for 6 pinned vertices"}, "too many");
  expectRefused(world.setPinTargets(cloth, {}), {"got 0 targets"}, "none");
}

TEST_F(BadInput, NonFinitePinTargets) {
  for (Real bad : {kNaN, kInf, -kInf}) {
    std::vector<Vec3> targets = world.pinTargets(cloth).value();
    targets[4].y() = bad;
    expectRefused(world.setPinTargets(cloth, targets), {"target 4", "vertex 28", "NaN or infinite"},
                  "non-finite target");
  }
}

TEST_F(BadInput, SetStateWithWrongSizesOrNonFiniteValues) {
  const std::span<const Vec3> x = world.positions(cloth).value();
  std::vector<Vec3> positions(x.begin(), x.end()), velocities(x.size(), Vec3::Zero());
  expectRefused(world.setState(cloth, std::span(positions).first(10), velocities),
                {"got 10 positions and 30 velocities", "30 vertices"}, "short positions");
  expectRefused(world.setState(cloth, positions, std::span(velocities).first(29)),
                {"30 positions and 29 velocities"}, "short velocities");
  positions[12].x() = kNaN;
  expectRefused(world.setState(cloth, positions, velocities), {"vertex 12", "NaN or infinite"},
                "NaN position");
  positions[12].x() = 0;
  velocities[3].z() = kInf;
  expectRefused(world.setState(cloth, positions, velocities), {"vertex 3"}, "infinite velocity");
}

// ------------------------------------------------------------------------- step

TEST_F(BadInput, NonPositiveOrNonFiniteFrameLength) {
  for (Real dt : {0.0, -1.0 / 60, -0.0, kNaN, kInf, -kInf}) {
    EXPECT_EQ(world.step(dt), StepStatus::InvalidInput) << dt;
    EXPECT_EQ(world.stats().status, StepStatus::InvalidInput);
    expectUnchanged("step");
  }
  for (Real dt : {0.0, kNaN}) {
    expectRefused(world.plannedSubsteps(cloth, dt), {"frameDt"}, "plannedSubsteps");
  }
}

// ------------------------------------------------------------------------- colliders

TEST_F(BadInput, ColliderWithBadFriction) {
  for (Real friction : {-0.1, kNaN, kInf}) {
    ColliderSettings settings;
    settings.friction = friction;
    expectRefused(world.addCollider(Sphere::create(0.2).value(), settings), {"friction"}, "friction");
  }
}

TEST_F(BadInput, ColliderMotionWithNaNOrNonUnitRotation) {
  RigidMotion bad;
  bad.pose.position = Vec3(kNaN, 0, 0);
  expectRefused(world.setColliderMotion(sphere, bad), {"position"}, "NaN position");
  bad = RigidMotion{};
  bad.pose.rotation = Quat(2, 0, 0, 0);
  expectRefused(world.setColliderMotion(sphere, bad), {"rotation", "norm 2"}, "non-unit rotation");
  bad = RigidMotion{};
  bad.pose.rotation.coeffs()(1) = kNaN;
  expectRefused(world.setColliderMotion(sphere, bad), {"rotation"}, "NaN rotation");
  bad = RigidMotion{};
  bad.linearVelocity = Vec3(0, kInf, 0);
  expectRefused(world.setColliderMotion(sphere, bad), {"linear velocity"}, "infinite velocity");
  bad = RigidMotion{};
  bad.angularVelocity = Vec3(0, 0, kNaN);
  expectRefused(world.setColliderMotion(sphere, bad), {"angular velocity"}, "NaN spin");
}

TEST(BadInputShapes, NegativeZeroOrNonFiniteSizes) {
  for (Real radius : {-0.1, 0.0, kNaN, kInf}) {
    EXPECT_THAT(Sphere::create(radius).error().message, HasSubstr("radius")) << radius;
    EXPECT_THAT(Capsule::create(radius, 0.5).error().message, HasSubstr("radius")) << radius;
    EXPECT_THAT(Box::create(Vec3(0.1, radius, 0.1)).error().message, HasSubstr("half extents"));
  }
  EXPECT_THAT(Capsule::create(0.1, -0.5).error().message, HasSubstr("Capsule"));
  EXPECT_THAT(Capsule::create(0.1, kNaN).error().message, HasSubstr("Capsule"));
  EXPECT_THAT(Plane::create(Vec3::Zero()).error().message, HasSubstr("normal"));
  EXPECT_THAT(Plane::create(Vec3(kNaN, 1, 0)).error().message, HasSubstr("normal"));
}

TEST(BadInputShapes, NaNPoseIsRefusedByEveryShape) {
  RigidMotion bad;
  bad.pose.position = Vec3(0, kNaN, 0);
  EXPECT_THAT(Sphere::create(0.1, bad).error().message, HasSubstr("Sphere"));
  EXPECT_THAT(Capsule::create(0.1, 0.2, bad).error().message, HasSubstr("Capsule"));
  EXPECT_THAT(Box::create(Vec3(0.1, 0.1, 0.1), bad).error().message, HasSubstr("Box"));
  EXPECT_THAT(Plane::create(Vec3(0, 1, 0), bad).error().message, HasSubstr("Plane"));
  const std::vector<Vec3> vertices{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const std::vector<Index> indices{0, 1, 2};
  EXPECT_THAT(TriangleMeshShape::create(vertices, indices, bad).error().message,
              HasSubstr("TriangleMeshShape"));
}

TEST(BadInputShapes, MalformedTriangleMeshes) {
  const std::vector<Vec3> vertices{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  EXPECT_THAT(TriangleMeshShape::create(vertices, std::vector<Index>{}).error().message,
              HasSubstr("no triangles"));
  EXPECT_FALSE(TriangleMeshShape::create(vertices, std::vector<Index>{0, 1}).ok());
  EXPECT_FALSE(TriangleMeshShape::create(vertices, std::vector<Index>{0, 1, 7}).ok());
  EXPECT_FALSE(TriangleMeshShape::create(vertices, std::vector<Index>{0, 1, 1}).ok());
  const std::vector<Vec3> nan{Vec3(0, 0, 0), Vec3(kNaN, 0, 0), Vec3(0, 1, 0)};
  EXPECT_FALSE(TriangleMeshShape::create(nan, std::vector<Index>{0, 1, 2}).ok());
  const std::vector<Vec3> flat{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  EXPECT_FALSE(TriangleMeshShape::create(flat, std::vector<Index>{0, 1, 2}).ok());
}

// ------------------------------------------------------------------------- save and restore

TEST_F(BadInput, RestoreAStateOfAnotherWorld) {
  World other;
  (void)other.createCloth(smallGrid(), pinnedTopRow()).value();
  (void)other.addCollider(Sphere::create(0.1).value()).value();
  // Same handles, same vertex count: only the world's identity tells the state apart.
  const WorldState foreign = other.saveState();
  expectRefused(world.restoreState(foreign), {"restoreState", "another World"}, "foreign state");
}

TEST_F(BadInput, RestoreAnEmptyState) {
  expectRefused(world.restoreState(WorldState{}), {"restoreState", "empty"}, "empty state");
}

TEST_F(BadInput, RestoreAMovedFromState) {
  WorldState saved = world.saveState();
  const WorldState taken = std::move(saved);
  // NOLINTNEXTLINE(bugprone-use-after-move): the point of the test
  expectRefused(world.restoreState(saved), {"restoreState", "empty"}, "moved-from state");
  const WorldState copyOfMoved = saved;
  expectRefused(world.restoreState(copyOfMoved), {"restoreState", "empty"}, "copy of a moved-from state");
  EXPECT_TRUE(world.restoreState(taken).ok());
}

TEST_F(BadInput, RestoreAfterTheCollidersWereDestroyed) {
  const WorldState saved = world.saveState();
  ASSERT_TRUE(world.destroyCollider(sphere).ok());
  sphere = world.addCollider(Sphere::create(0.1, RigidMotion{{Vec3(0, 0, -1)}}).value()).value();
  world.step(1.0 / 60);
  snapshot();
  expectRefused(world.restoreState(saved), {"restoreState", "destroyed collider"}, "collider gone");
}

// ------------------------------------------------------------------------- models and files

TEST(BadInputModel, BadGrids) {
  auto refused = [](void (*spoil)(GridSettings&)) {
    GridSettings grid;
    spoil(grid);
    Result<ClothModel> model = ClothModel::grid(grid);
    EXPECT_FALSE(model.ok());
    return model.ok() ? std::string() : model.error().message;
  };
  EXPECT_THAT(refused([](GridSettings& g) { g.columns = 1; }), HasSubstr("grid of 1 x 31"));
  EXPECT_THAT(refused([](GridSettings& g) { g.width = 0; }), HasSubstr("width"));
  EXPECT_THAT(refused([](GridSettings& g) { g.height = -1; }), HasSubstr("height"));
  EXPECT_THAT(refused([](GridSettings& g) { g.width = kNaN; }), HasSubstr("width"));
  EXPECT_THAT(refused([](GridSettings& g) { g.origin.x() = kInf; }), HasSubstr("origin"));
  EXPECT_THAT(refused([](GridSettings& g) { g.heightAxis = g.widthAxis; }), HasSubstr("heightAxis"));
}

TEST(BadInputModel, MalformedMeshes) {
  TriangleMesh good;
  good.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  good.indices = {0, 1, 2, 0, 2, 3};
  ASSERT_TRUE(ClothModel::fromMesh(good).ok());
  auto refused = [&](void (*spoil)(TriangleMesh&)) {
    TriangleMesh mesh = good;
    spoil(mesh);
    Result<ClothModel> model = ClothModel::fromMesh(mesh);
    EXPECT_FALSE(model.ok());
    return model.ok() ? std::string() : model.error().message;
  };
  EXPECT_THAT(refused([](TriangleMesh& m) { m.indices.clear(); }), HasSubstr("empty"));
  EXPECT_THAT(refused([](TriangleMesh& m) { m.indices.pop_back(); }), HasSubstr("indices"));
  EXPECT_THAT(refused([](TriangleMesh& m) { m.indices[4] = 9; }), HasSubstr("index 9"));
  EXPECT_THAT(refused([](TriangleMesh& m) { m.indices[1] = 0; }), HasSubstr("repeated vertex index 0"));
  EXPECT_THAT(refused([](TriangleMesh& m) { m.positions[2].z() = kNaN; }), HasSubstr("vertex 2"));
  EXPECT_THAT(refused([](TriangleMesh& m) { m.positions[2] = Vec3(0.5, 0, 0); }), HasSubstr("triangle 0"));
  EXPECT_THAT(refused([](TriangleMesh& m) { m.materialCoordinates.assign(3, Vec2::Zero()); }),
              HasSubstr("material coordinates"));
  EXPECT_THAT(refused([](TriangleMesh& m) {
                m.positions.push_back(Vec3(1, 1, 1));
                m.indices.insert(m.indices.end(), {0, 2, 4});  // a third triangle on edge (0, 2)
              }),
              HasSubstr("edge (0, 2)"));
}

TEST(BadInputModel, ZeroWarpDirection) {
  TriangleMesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  mesh.indices = {0, 1, 2};
  MeshSettings settings;
  settings.warpDirection = Vec3::Zero();
  EXPECT_THAT(ClothModel::fromMesh(mesh, settings).error().message, HasSubstr("warpDirection"));
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(BadInputFiles, UnreadablePathOrDirectory) {
  EXPECT_THAT(ClothModel::loadObj("/nonexistent/weft/bad.obj").error().message,
              HasSubstr("/nonexistent/weft/bad.obj"));
  const std::string directory = std::filesystem::temp_directory_path().string();
  EXPECT_THAT(ClothModel::loadObj(directory).error().message, HasSubstr(directory));
  EXPECT_FALSE(ClothModel::loadObj("").ok());
}

TEST(BadInputFiles, MalformedObjFiles) {
  struct Case {
    const char* name;
    const char* text;
  } cases[] = {
      {"weft_bad_garbage.obj", "this is not an OBJ file\n\x01\x02\x03\n"},
      {"weft_bad_empty.obj", ""},
      {"weft_bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"},
      {"weft_bad_negative_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -7\n"},
      {"weft_bad_nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"},
      {"weft_bad_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"},
      {"weft_bad_repeated.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n"},
      {"weft_bad_no_faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"},
  };
  for (const Case& c : cases) {
    const std::string path = writeFile(c.name, c.text);
    Result<ClothModel> model = ClothModel::loadObj(path);
    ASSERT_FALSE(model.ok()) << c.name;
    EXPECT_THAT(model.error().message, HasSubstr(c.name)) << "the message names the file";
    std::remove(path.c_str());
  }
}

TEST(BadInputFiles, NonFiniteObjCoordinatesNameTheLine) {
  for (const char* number : {"nan", "-nan", "inf", "-inf", "infinity", "1e400", "-2e308"}) {
    const std::string text = std::string("v 0 0 0\nv 1 0 0\n# a comment\nv 0 ") + number + " 0\nf 1 2 3\n";
    Result<TriangleMesh> mesh = ClothModel::parseObj(text, "OBJ file 'cape.obj'");
    ASSERT_FALSE(mesh.ok()) << number;
    EXPECT_THAT(mesh.error().message, HasSubstr("OBJ file 'cape.obj', line 4: coordinate '")) << number;
    EXPECT_THAT(mesh.error().message, HasSubstr("of vertex 3 is not a finite number")) << number;
  }
  // Underflow is a coordinate of 0, not an error.
  Result<TriangleMesh> tiny = ClothModel::parseObj("v 0 0 1e-400\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_TRUE(tiny.ok()) << tiny.error().message;
  EXPECT_EQ(tiny->positions[0].z(), 0.0);
  EXPECT_THAT(ClothModel::parseObj("v 0 0\nf 1 1 1\n").error().message,
              HasSubstr("line 1: vertex 1 has 2 coordinates; write 'v x y z'"));
  EXPECT_THAT(ClothModel::parseObj("v 0 zero 0\n").error().message,
              HasSubstr("line 1: coordinate 'zero' of vertex 1 is not a number"));
}

TEST(BadInputFiles, ObjFaceIndicesOutOfEveryRangeNameTheLine) {
  const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  struct Case {
    const char* face;
    const char* message;
  } cases[] = {
      {"f 1 2 99999999999999999999999", "line 4: vertex index '99999999999999999999999' is too large for any integer"},
      {"f 1 2 -99999999999999999999999", "line 4: vertex index '-99999999999999999999999' is too large for any integer"},
      {"f 1 2 4294967296", "line 4: vertex index 4294967296 is beyond any cloth model's vertices"},
      {"f 1 2 2147483648", "line 4: vertex index 2147483648 is out of range; the file has 3 vertices"},
      {"f 1 2 4", "line 4: vertex index 4 is out of range; the file has 3 vertices"},
      {"f 1 2 0", "line 4: vertex index 0 is invalid"},
      {"f 1 2 -4", "line 4: vertex index -4 reaches before the first vertex"},
      {"f 1 2", "line 4: a face needs at least three vertices, this one has 2"},
      {"f 1/1 2/x/ a/3", "line 4: face corner 'a/3' does not start with a vertex index"},
  };
  for (const Case& c : cases) {
    Result<TriangleMesh> mesh = ClothModel::parseObj(vertices + c.face + "\n");
    ASSERT_FALSE(mesh.ok()) << c.face;
    EXPECT_THAT(mesh.error().message, HasSubstr(c.message)) << c.face;
  }
  // Relative indices count back from the last vertex read: -1 -2 -3 is 3 2 1.
  Result<TriangleMesh> relative = ClothModel::parseObj(vertices + "f -1 -2 -3\n");
  ASSERT_TRUE(relative.ok()) << relative.error().message;
  EXPECT_EQ(relative->indices, (std::vector<Index>{2, 1, 0}));
}

TEST(BadInputFiles, ObjPolygonsAreSplitInsideTheirOutline) {
  // A concave quad (an arrowhead) and an L-shaped hexagon: every triangle keeps the outline's
  // winding (+z) and the areas sum to the polygon's.
  const char* text =
      "v 0 0 0\nv 2 1 0\nv 0 2 0\nv 0.5 1 0\n"             // arrowhead, reflex corner 4
      "v 3 0 0\nv 5 0 0\nv 5 1 0\nv 4 1 0\nv 4 2 0\nv 3 2 0\n"  // L, reflex corner 8
      "f 1 2 3 4\nf 5 6 7 8 9 10\n";
  Result<TriangleMesh> mesh = ClothModel::parseObj(text);
  ASSERT_TRUE(mesh.ok()) << mesh.error().message;
  ASSERT_EQ(mesh->indices.size(), 3u * (2 + 4));
  Real arrow = 0, ell = 0;
  for (std::size_t t = 0; t < mesh->indices.size() / 3; ++t) {
    const Vec3& a = mesh->positions[mesh->indices[3 * t]];
    const Vec3& b = mesh->positions[mesh->indices[3 * t + 1]];
    const Vec3& c = mesh->positions[mesh->indices[3 * t + 2]];
    const Real signedArea = 0.5 * (b - a).cross(c - a).z();
    EXPECT_GT(signedArea, 0) << "triangle " << t;
    (t < 2 ? arrow : ell) += signedArea;
  }
  EXPECT_NEAR(arrow, 1.5, 1e-12);
  EXPECT_NEAR(ell, 3.0, 1e-12);
}

TEST(BadInputFiles, DevicesFifosAndDirectoriesAreRefusedUnread) {
  // /dev/zero would never end; a FIFO without a writer would block on open.
  const auto start = std::chrono::steady_clock::now();
  for (const char* device : {"/dev/zero", "/dev/urandom", "/dev/null"}) {
    Result<TriangleMesh> mesh = ClothModel::readObj(device);
    ASSERT_FALSE(mesh.ok()) << device;
    EXPECT_THAT(mesh.error().message, HasSubstr(std::string("OBJ file '") + device + "'"));
    EXPECT_THAT(mesh.error().message, HasSubstr("is a character device, not a regular file"));
  }
  const std::string fifo = (std::filesystem::temp_directory_path() / "weft_bad_fifo.obj").string();
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THAT(ClothModel::loadObj(fifo).error().message, HasSubstr("is a FIFO (named pipe)"));
  std::remove(fifo.c_str());
  const std::string directory = std::filesystem::temp_directory_path().string();
  EXPECT_THAT(ClothModel::readObj(directory).error().message, HasSubstr("is a directory"));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(BadInputFiles, FilesAboveTheLimitAreRefusedUnread) {
  // A sparse file one byte over the OBJ limit: no disk space, and the reader must not read it.
  const std::string path = (std::filesystem::temp_directory_path() / "weft_bad_huge.obj").string();
  std::ofstream(path).close();
  ASSERT_EQ(::truncate(path.c_str(), off_t(ClothModel::kMaxObjFileBytes + 1)), 0);
  const long long live = test::heapLiveBytes();
  test::resetHeapPeak();
  Result<TriangleMesh> mesh = ClothModel::readObj(path);
  ASSERT_FALSE(mesh.ok());
  EXPECT_THAT(mesh.error().message, HasSubstr("weft_bad_huge.obj' is 1073741825 bytes, more than the limit of 1073741824 bytes (1.1 GB) for OBJ files"));
  EXPECT_LT(test::heapPeakBytes() - live, 1 << 20) << "the file was read";
  std::remove(path.c_str());
  // A file whose size the file system does not tell (/proc) is cut off one byte past the limit.
  Result<std::string> status = readInputFile("/proc/self/status", 16, "status file");
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.error().message, HasSubstr("is larger than the limit of 16 bytes for status files (found while reading it"));
  ASSERT_TRUE(readInputFile("/proc/self/status", 1 << 20, "status file").ok());
}

TEST(BadInputModel, GridsBeyondTheIndexRangeAreRefusedBeforeAllocating) {
  struct Case {
    Index columns, rows;
  } cases[] = {{100000, 100000}, {65536, 65536}, {70000, 60000}, {4000000000u, 2}};
  for (const Case& c : cases) {
    GridSettings grid;
    grid.columns = c.columns;
    grid.rows = c.rows;
    test::resetHeapPeak();
    const long long live = test::heapLiveBytes();
    Result<ClothModel> model = ClothModel::grid(grid);
    ASSERT_FALSE(model.ok()) << c.columns << " x " << c.rows;
    EXPECT_THAT(model.error().message, HasSubstr("grid of " + std::to_string(c.columns) + " x " +
                                                 std::to_string(c.rows) + " vertices"));
    EXPECT_THAT(model.error().message, HasSubstr("(32-bit indices): use fewer columns and rows"));
    EXPECT_LT(test::heapPeakBytes() - live, 1 << 16) << "allocated before refusing";
  }
}

TEST(BadInputModel, GridsBeyondTheMemoryAreRefusedBeforeAllocating) {
  // 2·10⁹ vertices and 4·10⁹ triangles fit 32-bit indices, but not any machine's memory.
  GridSettings grid;
  grid.columns = 50000;
  grid.rows = 40000;
  test::resetHeapPeak();
  const long long live = test::heapLiveBytes();
  Result<ClothModel> model = ClothModel::grid(grid);
  ASSERT_FALSE(model.ok());
  EXPECT_THAT(model.error().message, ::testing::ContainsRegex(
      "grid of 50000 x 40000 vertices needs about [0-9.]+ TB of memory, but [0-9.]+ [kMGT]B"));
  EXPECT_THAT(model.error().message, HasSubstr("are available; use fewer columns and rows"));
  EXPECT_LT(test::heapPeakBytes() - live, 1 << 16) << "allocated before refusing";
}

TEST(BadInputModel, MemoryEstimatesHoldWhatAClothReallyTakes) {
  // 101 x 101 vertices: the heap's peak while the model is built (grid() and fromMesh()) and
  // while a cloth is created and steps its first frames, against the estimates the engine
  // checks before allocating. An estimate must cover the peak, and be honest: within 2x of it.
  GridSettings grid;
  grid.columns = grid.rows = 101;
  grid.width = grid.height = 1.0;
  test::resetHeapPeak();
  long long live = test::heapLiveBytes();
  auto model = std::make_shared<const ClothModel>(ClothModel::grid(grid).value());
  const long long gridPeak = test::heapPeakBytes() - live;
  TriangleMesh mesh;
  mesh.positions = model->restPositions();
  mesh.indices = model->indices();
  test::resetHeapPeak();
  live = test::heapLiveBytes();
  ASSERT_TRUE(ClothModel::fromMesh(mesh).ok());
  const long long meshPeak = test::heapPeakBytes() - live;
  const long long modelEstimate =
      static_cast<long long>(ClothModel::estimatedBuildBytes(model->vertexCount(), model->triangleCount()));
  EXPECT_LE(gridPeak, modelEstimate);
  EXPECT_LE(meshPeak, modelEstimate);
  EXPECT_GE(2 * std::max(gridPeak, meshPeak), modelEstimate);

  WorldSettings settings;
  settings.threadCount = 1;
  World world(settings);
  ClothSettings cloth;
  for (Index column = 0; column < 101; ++column) cloth.pinnedVertices.push_back(100 * 101 + column);
  test::resetHeapPeak();
  live = test::heapLiveBytes();
  ASSERT_TRUE(world.createCloth(model, cloth).ok());
  for (int frame = 0; frame < 3; ++frame) world.step(1.0 / 60.0);
  const long long clothPeak = test::heapPeakBytes() - live;
  const long long clothEstimate =
      static_cast<long long>(World::estimatedClothBytes(model->vertexCount(), model->triangleCount()));
  EXPECT_LE(clothPeak, clothEstimate);
  EXPECT_GE(2 * clothPeak, clothEstimate);
  std::printf("[memory] per vertex: grid() %.0f B, fromMesh() %.0f B (estimate %.0f B); cloth %.0f B "
              "(estimate %.0f B)\n", double(gridPeak) / model->vertexCount(),
              double(meshPeak) / model->vertexCount(), double(modelEstimate) / model->vertexCount(),
              double(clothPeak) / model->vertexCount(), double(clothEstimate) / model->vertexCount());
}

TEST(BadInputModel, MemoryCheckNamesTheInputAndTheFix) {
  EXPECT_TRUE(checkMemory(1000, "a cloth", "use fewer vertices").ok());
  Status huge = checkMemory(std::uint64_t(1) << 60, "a cloth of 7 vertices", "use fewer vertices");
  ASSERT_FALSE(huge.ok());
  EXPECT_THAT(huge.error().message, HasSubstr("a cloth of 7 vertices needs about 1.2 EB of memory, but"));
  EXPECT_THAT(huge.error().message, HasSubstr("are available; use fewer vertices"));
  const std::uint64_t available = availableMemoryBytes();
  EXPECT_GT(available, 0u);
  EXPECT_EQ(formatBytes(999), "999 bytes");
  EXPECT_EQ(formatBytes(6'100'000'000'000), "6.1 TB");
  EXPECT_EQ(formatBytes(27'000'000'000), "27 GB");
}

TEST(BadInputModel, PositionsBeyondTheLargestCoordinateAreRefused) {
  TriangleMesh mesh;
  mesh.positions = {Vec3(0, 0, 0), Vec3(1e30, 0, 0), Vec3(0, 1e30, 0)};
  mesh.indices = {0, 1, 2};
  EXPECT_THAT(ClothModel::fromMesh(mesh).error().message,
              HasSubstr("position of vertex 1 is (1e+30, 0, 0) m, beyond the 1e+06 m a coordinate may have (kMaxCoordinate)"));
  GridSettings grid;
  grid.origin = Vec3(0, -1e30, 0);
  EXPECT_THAT(ClothModel::grid(grid).error().message, HasSubstr("kMaxCoordinate"));
  grid = GridSettings{};
  grid.width = 1e300;
  EXPECT_THAT(ClothModel::grid(grid).error().message, HasSubstr("kMaxCoordinate"));
  // Just inside is a model (a 1 m sheet 999 km away).
  grid = GridSettings{};
  grid.origin = Vec3(9.99e5, 0, 0);
  grid.width = grid.height = 0.5;
  EXPECT_TRUE(ClothModel::grid(grid).ok());
}

TEST_F(BadInput, ClothsPlacedBeyondTheLargestCoordinateAreRefused) {
  for (const Vec3& translation : {Vec3(1e30, 0, 0), Vec3(0, -2e6, 0), Vec3(0, 0, 1e300)}) {
    ClothSettings settings = pinnedTopRow();
    settings.translation = translation;
    expectRefused(world.createCloth(smallGrid(), settings), {"cloth settings: translation", "kMaxCoordinate"},
                  "far translation");
  }
  const std::span<const Vec3> x = world.positions(cloth).value();
  std::vector<Vec3> positions(x.begin(), x.end()), velocities(x.size(), Vec3::Zero());
  positions[7].y() = 1e30;
  expectRefused(world.setState(cloth, positions, velocities), {"setState: vertex 7", "kMaxCoordinate"},
                "far state");
  std::vector<Vec3> targets = world.pinTargets(cloth).value();
  targets[2].x() = -1e30;
  expectRefused(world.setPinTargets(cloth, targets), {"setPinTargets: target 2", "kMaxCoordinate"},
                "far pin target");
}

TEST_F(BadInput, ValuesBeyondWhatTheArithmeticCarriesAreRefused) {
  // 1e300 N/m overflows the solver's norms: it froze the cloth with solver-not-converged.
  for (Real value : {1e300, 2 * kMaxMaterialValue}) {
    ClothSettings settings = pinnedTopRow();
    settings.material.warpStretchStiffness = value;
    expectRefused(world.createCloth(smallGrid(), settings),
                  {"cloth settings: material.warpStretchStiffness = ", "N/m is above 1e+30 (kMaxMaterialValue)"},
                  "stiffness");
    settings = pinnedTopRow();
    settings.material.arealDensity = value;
    expectRefused(world.createCloth(smallGrid(), settings), {"material.arealDensity", "kMaxMaterialValue"},
                  "density");
    settings = pinnedTopRow();
    settings.springs.flexionDamping = value;
    expectRefused(world.createCloth(smallGrid(), settings), {"springs.flexionDamping", "kMaxMaterialValue"},
                  "spring damping");
    settings = pinnedTopRow();
    settings.vertexMasses.assign(kColumns * kRows, 0.01);
    settings.vertexMasses[4] = value;
    expectRefused(world.createCloth(smallGrid(), settings), {"vertexMasses[4]", "kMaxMaterialValue"}, "mass");
  }
  std::vector<Vec3> forces(kColumns * kRows, Vec3::Zero());
  forces[11] = Vec3(0, 0, 1e300);
  expectRefused(world.setExternalForces(cloth, forces),
                {"setExternalForces: the force on vertex 11", "kMaxMaterialValue"}, "force");
}

TEST_F(BadInput, GravityWindAndSpeedsBeyondTheLimitsAreRefused) {
  // Gravity of 1e30 m/s² let the self-collision fail-safe hold a diverged cloth still while
  // every frame said "ok".
  expectRefused(world.setGravity(Vec3(0, -1e30, 0)), {"setGravity: gravity", "kMaxGravity"}, "gravity");
  expectRefused(world.setGravity(Vec3(0, -1.01 * kMaxGravity, 0)), {"kMaxGravity"}, "gravity");
  expectRefused(world.setWind(Vec3(1e30, 0, 0)), {"setWind: the wind", "kMaxSpeed"}, "wind");
  const std::span<const Vec3> x = world.positions(cloth).value();
  std::vector<Vec3> positions(x.begin(), x.end()), velocities(x.size(), Vec3::Zero());
  velocities[3] = Vec3(0, 0, 1e30);
  expectRefused(world.setState(cloth, positions, velocities),
                {"setState: the velocity of vertex 3", "faster than 10000 m/s (kMaxSpeed"}, "velocity");
  RigidMotion fast = motion(*world.collider(sphere).value());
  fast.linearVelocity = Vec3(0, 0, -1e30);
  expectRefused(world.setColliderMotion(sphere, fast), {"setColliderMotion: the linear velocity", "kMaxSpeed"},
                "collider speed");
  expectRefused(world.addCollider(Sphere::create(0.1, fast).value()),
                {"addCollider: the collider's linear velocity", "kMaxSpeed"}, "new collider speed");
  for (const Vec3& gravity : {Vec3(0, -1e30, 0), Vec3(kNaN, 0, 0)}) {
    WorldSettings settings;
    settings.gravity = gravity;
    EXPECT_THAT(World::create(settings).error().message, HasSubstr("WorldSettings::gravity"));
  }
  WorldSettings windy;
  windy.wind = Vec3(0, 2e4, 0);
  EXPECT_THAT(World::create(windy).error().message, HasSubstr("WorldSettings::wind"));
}

TEST_F(BadInput, AClockThatWouldOverflowIsRefused) {
  // Two frames of 1e308 s would take the world's time to infinity.
  ASSERT_FALSE(hasFlag(world.step(1e308), StepStatus::InvalidInput));
  snapshot();
  EXPECT_EQ(world.step(1e308), StepStatus::InvalidInput);
  expectUnchanged("clock overflow");
}

// A cloth at the edge of what the engine takes, legal: it steps, stays finite, and its flags are
// the ones the frame earned.
struct ExtremeRun {
  StepStatus flags = StepStatus::Ok;
  bool finite = true;
  bool moved = false;
};

ExtremeRun runExtreme(void (*spoil)(ClothSettings&, WorldSettings&), Real frameDt, int frames) {
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  worldSettings.wind = Vec3(0, 0, 2);
  ClothSettings settings = pinnedTopRow();
  spoil(settings, worldSettings);
  World world(worldSettings);
  const ClothId cloth = world.createCloth(smallGrid(), settings).value();
  const std::uint64_t start = world.stateHash();
  ExtremeRun run;
  for (int frame = 0; frame < frames; ++frame) {
    const StepStatus status = world.step(frameDt);
    EXPECT_EQ(world.stats().status, status);
    run.flags |= status;
  }
  for (const Vec3& x : world.positions(cloth).value()) run.finite = run.finite && x.allFinite();
  for (const Vec3& v : world.velocities(cloth).value()) run.finite = run.finite && v.allFinite();
  run.moved = world.stateHash() != start;
  return run;
}

TEST(BadInputExtremes, FrameLengthsOfAnAttosecondAndOfElevenDaysRunFinitely) {
  // 1e-300 s: nothing can move in it; every check passes.
  ExtremeRun tiny = runExtreme([](ClothSettings&, WorldSettings&) {}, 1e-300, 3);
  EXPECT_TRUE(tiny.finite);
  EXPECT_EQ(tiny.flags, StepStatus::Ok);
  EXPECT_FALSE(tiny.moved);
  // 1e6 s: more implicit substeps than SolverSettings::maxSubsteps allows, which the flags say.
  ExtremeRun huge = runExtreme([](ClothSettings&, WorldSettings&) {}, 1e6, 3);
  EXPECT_TRUE(huge.finite);
  EXPECT_TRUE(hasFlag(huge.flags, StepStatus::Unstable)) << describe(huge.flags);
}

TEST(BadInputExtremes, ValuesAtTheLimitsRunFinitely) {
  using Spoil = void (*)(ClothSettings&, WorldSettings&);
  const struct {
    const char* name;
    Spoil spoil;
  } cases[] = {
      {"stretch stiffness", [](ClothSettings& s, WorldSettings&) {
         s.material.warpStretchStiffness = s.material.weftStretchStiffness = kMaxMaterialValue; }},
      {"bending stiffness", [](ClothSettings& s, WorldSettings&) { s.material.bendingStiffness = kMaxMaterialValue; }},
      {"density", [](ClothSettings& s, WorldSettings&) { s.material.arealDensity = kMaxMaterialValue; }},
      {"damping", [](ClothSettings& s, WorldSettings&) { s.material.stretchDamping = kMaxMaterialValue; }},
      {"spring stiffness", [](ClothSettings& s, WorldSettings&) {
         s.forceModel = ForceModel::MassSpring;
         s.springs.structuralStiffness = kMaxMaterialValue; }},
      {"gravity", [](ClothSettings&, WorldSettings& w) { w.gravity = Vec3(0, -kMaxGravity, 0); }},
      {"wind", [](ClothSettings&, WorldSettings& w) { w.wind = Vec3(0, 0, kMaxSpeed); }},
  };
  for (const auto& c : cases) {
    const ExtremeRun run = runExtreme(c.spoil, 1.0 / 60.0, 20);
    EXPECT_TRUE(run.finite) << c.name;
    EXPECT_TRUE(run.moved) << c.name;
  }
}

TEST(BadInputExtremes, ASliverJustAboveTheDegenerateThresholdRunsFinitely) {
  // A unit square and a sliver on its right edge, of area just above degenerateAreaRatio times
  // its longest edge squared (and one just below, refused naming it).
  auto withSliver = [](Real areaRatio) {
    TriangleMesh mesh;
    const Real height = 2 * areaRatio * 0.1;  // area = 0.1 · height / 2 over a longest edge of 0.1
    mesh.positions = {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.1, 0.1, 0), Vec3(0, 0.1, 0),
                      Vec3(0.1 + height, 0.05, 0)};
    mesh.indices = {0, 1, 2, 0, 2, 3, 1, 4, 2};
    return mesh;
  };
  const Real threshold = MeshSettings{}.degenerateAreaRatio;
  EXPECT_THAT(ClothModel::fromMesh(withSliver(0.99 * threshold)).error().message,
              HasSubstr("triangle 2 (vertices 1, 4, 2): degenerate"));
  Result<ClothModel> model = ClothModel::fromMesh(withSliver(1.01 * threshold));
  ASSERT_TRUE(model.ok()) << model.error().message;
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  worldSettings.wind = Vec3(0, 0, 2);
  World world(worldSettings);
  ClothSettings settings;
  settings.pinnedVertices = {2, 3};
  const ClothId cloth = world.createCloth(std::make_shared<const ClothModel>(std::move(model).value()), settings).value();
  for (int frame = 0; frame < 60; ++frame) {
    const StepStatus status = world.step(1.0 / 60.0);
    ASSERT_FALSE(hasFlag(status, StepStatus::RolledBack)) << frame << ": " << describe(status);
  }
  for (const Vec3& x : world.positions(cloth).value()) EXPECT_TRUE(x.allFinite());
  // The wind carried the free corner out of the plane: the sliver did not lock the cloth.
  EXPECT_GT(std::abs(world.positions(cloth).value()[0].z()), 0.01);
}

TEST(BadInputWorld, ThreadCountsOutOfRangeAreRefusedNamingTheField) {
  for (int count : {-1, -64, TaskSystemSettings::kMaxThreadCount + 1, INT_MAX, INT_MIN}) {
    WorldSettings settings;
    settings.threadCount = count;
    const std::string field = "WorldSettings::threadCount = " + std::to_string(count);
    Result<World> checked = World::create(settings);
    ASSERT_FALSE(checked.ok()) << count;
    EXPECT_THAT(checked.error().message, HasSubstr(field));
    EXPECT_THAT(checked.error().message, HasSubstr("give 0 (the machine's cores), 1 (serial) or up to 1024"));
    // Unchecked, the world runs serially (no thread pool of a mistaken size) and refuses cloths.
    World unchecked(settings);
    EXPECT_EQ(unchecked.threadCount(), 1);
    EXPECT_THAT(unchecked.createCloth(smallGrid(), {}).error().message, HasSubstr(field));
    EXPECT_EQ(unchecked.clothCount(), 0u);
    EXPECT_THAT(validate(TaskSystemSettings{count}), HasSubstr("TaskSystemSettings::threadCount = " + std::to_string(count)));
    EXPECT_EQ(TaskSystem(TaskSystemSettings{count}).threadCount(), 1);
  }
  for (int count : {0, 1, 2}) {
    WorldSettings settings;
    settings.threadCount = count;
    EXPECT_TRUE(World::create(settings).ok()) << count;
    EXPECT_TRUE(validate(TaskSystemSettings{count}).empty()) << count;
  }
}

TEST(BadInputPresets, UnknownFabricName) {
  Result<ClothMaterial> preset = fabricPreset("velvet");
  ASSERT_FALSE(preset.ok());
  EXPECT_THAT(preset.error().message, HasSubstr("velvet"));
  EXPECT_THAT(preset.error().message, HasSubstr("cotton"));
}

}  // namespace
}  // namespace weft
