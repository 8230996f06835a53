// Bad input at every public entry point (issue 9): each case is refused with a message that
// names the input, and a world it was handed to is left exactly as it was (state hash, time,
// cloth count, pin targets and collider poses compared before and after).
#include <weft/engine/FabricPresets.h>
#include <weft/engine/World.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

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

TEST(BadInputPresets, UnknownFabricName) {
  Result<ClothMaterial> preset = fabricPreset("velvet");
  ASSERT_FALSE(preset.ok());
  EXPECT_THAT(preset.error().message, HasSubstr("velvet"));
  EXPECT_THAT(preset.error().message, HasSubstr("cotton"));
}

}  // namespace
}  // namespace weft
