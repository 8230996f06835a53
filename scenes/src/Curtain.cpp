#include <weft/scenes/Curtain.h>

#include <algorithm>
#include <cmath>

namespace weft {
namespace {

// C¹ ease in and out over [0, 1], so the rod starts and stops without a jerk.
Real smoothstep(Real s) {
  s = std::clamp<Real>(s, 0, 1);
  return s * s * (3 - 2 * s);
}

}  // namespace

std::span<const CurtainPhase> CurtainScene::phases() {
  static constexpr CurtainPhase kPhases[] = {
      {0, 1, "settle"},        {1, 2, "sphere pushes"}, {2, 3, "sphere withdraws"},
      {3, 4, "swing"},         {4, 6, "rod gathers"},   {6, 8, "hold"},
      {8, 10, "rod opens"}};
  return kPhases;
}

std::array<Index, 2> CurtainScene::gridSize(Index size) {
  const Index refinement = size == 64 ? 8 : size == 16 ? 4 : size == 4 ? 2 : 1;
  return {40 * refinement + 1, 30 * refinement + 1};
}

Vec3 CurtainScene::pinTarget(const Vec3& restPosition, Real t) {
  // Gather between 4 and 6 s, hold until 8 s, open again by 10 s. The left end (x = −1) stays.
  Real gathered = 0;
  if (t > 4 && t <= 6) gathered = smoothstep((t - 4) / 2);
  else if (t > 6 && t <= 8) gathered = 1;
  else if (t > 8) gathered = 1 - smoothstep((t - 8) / 2);
  const Real scale = 1 - (1 - kGatheredFraction) * gathered;
  return Vec3(-1 + (restPosition.x() + 1) * scale, restPosition.y(), restPosition.z());
}

Vec3 CurtainScene::spherePosition(Real t) {
  // Behind the curtain at z = −0.5; in to z = +0.3 between 1 and 2 s, back out by 3 s.
  Real pushed = 0;
  if (t > 1 && t <= 2) pushed = smoothstep(t - 1);
  else if (t > 2 && t <= 3) pushed = 1 - smoothstep(t - 2);
  return Vec3(0.3, 1.1, -0.5 + 0.8 * pushed);
}

Result<CurtainScene> CurtainScene::create(const CurtainSettings& settings) {
  if (settings.size != 1 && settings.size != 4 && settings.size != 16 && settings.size != 64) {
    return Error{"curtain size " + std::to_string(settings.size) +
                 " is not offered: choose 1, 4, 16 or 64"};
  }
  GridSettings grid;  // the defaults are the curtain's geometry
  const std::array<Index, 2> dimensions = gridSize(settings.size);
  grid.columns = dimensions[0];
  grid.rows = dimensions[1];
  Result<ClothModel> model = ClothModel::grid(grid);
  if (!model.ok()) return model.error();

  CurtainScene scene;
  scene.m_model = std::make_shared<const ClothModel>(std::move(model).value());
  WorldSettings worldSettings;
  worldSettings.threadCount = settings.threadCount;
  worldSettings.taskSystem = settings.taskSystem;
  worldSettings.skipUnneededStages = settings.skipUnneededStages;
  Result<World> world = World::create(worldSettings);
  if (!world.ok()) return Error{"curtain settings: " + world.error().message};
  scene.m_world = std::make_unique<World>(std::move(world).value());
  scene.m_pinScript = settings.pinScript;

  ClothSettings cloth;
  cloth.forceModel = settings.forceModel;
  cloth.material = settings.material;
  cloth.solver = settings.solver;
  cloth.selfCollision = settings.selfCollision;
  cloth.sleep.enabled = settings.sleep;
  const Index topRow = grid.rows - 1;
  for (Index column = 0; column < grid.columns; ++column) {
    cloth.pinnedVertices.push_back(topRow * grid.columns + column);
  }
  for (Index vertex : cloth.pinnedVertices) {
    scene.m_pinRest.push_back(scene.m_model->restPositions()[vertex]);
  }
  scene.m_targets = scene.m_pinRest;
  Result<ClothId> id = scene.m_world->createCloth(scene.m_model, cloth);
  if (!id.ok()) return id.error();
  scene.m_cloth = id.value();

  if (settings.sphere) {
    RigidMotion start;
    start.pose.position = spherePosition(0);
    Result<Sphere> sphere = Sphere::create(kSphereRadius, start);
    if (!sphere.ok()) return sphere.error();
    Result<ColliderId> sphereId = scene.m_world->addCollider(sphere.value());
    if (!sphereId.ok()) return sphereId.error();
    scene.m_sphere = sphereId.value();
    Result<Plane> floor = Plane::create(Vec3(0, 1, 0));
    if (!floor.ok()) return floor.error();
    Result<ColliderId> floorId = scene.m_world->addCollider(floor.value());
    if (!floorId.ok()) return floorId.error();
    scene.m_floor = floorId.value();
  }

  if (settings.initialWaviness != 0) {
    if (!std::isfinite(settings.initialWaviness)) {
      return Error{"curtain initialWaviness must be finite (metres)"};
    }
    constexpr Real kPleatWavelength = 0.25;  // m: eight pleats across the 2 m curtain
    constexpr Real kPi = 3.14159265358979323846;
    const Vec3Array& rest = scene.m_model->restPositions();
    Vec3Array positions = rest;
    for (Vec3& p : positions) {
      const Real fade = (grid.origin.y() + grid.height - p.y()) / grid.height;  // 0 at the rod
      p.z() += settings.initialWaviness * fade * std::sin(2 * kPi * (p.x() + 1) / kPleatWavelength);
    }
    const Vec3Array velocities(positions.size(), Vec3::Zero());
    Status state = scene.m_world->setState(scene.m_cloth, positions, velocities);
    if (!state.ok()) return state.error();
  }
  return scene;
}

StepStatus CurtainScene::stepFrame() {
  scriptFrame();
  return m_world->step(kFrameDt);
}

StepStatus CurtainScene::stepFrame(const StepBudget& budget) {
  scriptFrame();
  return m_world->step(kFrameDt, budget);
}

StepStatus CurtainScene::stepFrame(const StepPlan& plan) {
  scriptFrame();
  return m_world->step(kFrameDt, plan);
}

void CurtainScene::scriptFrame() {
  if (m_pinScript) {
    const Real endTime = (m_frame + 1) * kFrameDt;
    for (std::size_t k = 0; k < m_pinRest.size(); ++k) m_targets[k] = pinTarget(m_pinRest[k], endTime);
    // Cannot fail: one finite target per pin, on a live handle.
    (void)m_world->setPinTargets(m_cloth, m_targets);
  }
  if (!m_sphere.isNull()) {
    // Velocity that brings the sphere where the script wants it at the end of the frame.
    const Real endTime = (m_frame + 1) * kFrameDt;
    RigidMotion sphereMotion = motion(*m_world->collider(m_sphere).value());
    sphereMotion.linearVelocity = (spherePosition(endTime) - sphereMotion.pose.position) / kFrameDt;
    (void)m_world->setColliderMotion(m_sphere, sphereMotion);
  }
  ++m_frame;
}

}  // namespace weft
