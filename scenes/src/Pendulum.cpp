#include <weft/scenes/Pendulum.h>

#include <cmath>

namespace weft {

Result<PendulumScene> PendulumScene::create(const PendulumSettings& settings) {
  if (!(settings.length > 0) || !std::isfinite(settings.length)) {
    return Error{"pendulum length must be a positive number of metres"};
  }
  if (!std::isfinite(settings.amplitude) || std::abs(settings.amplitude) >= 1.5) {
    return Error{"pendulum amplitude must be finite and below 1.5 rad"};
  }
  TriangleMesh mesh;
  mesh.positions = {Vec3(-0.5, 0, 0), Vec3(0.5, 0, 0),
                    Vec3(0, -settings.length * std::cos(settings.amplitude),
                         settings.length * std::sin(settings.amplitude))};
  mesh.indices = {0, 1, 2};
  Result<ClothModel> model = ClothModel::fromMesh(mesh);
  if (!model.ok()) return model.error();
  auto shared = std::make_shared<const ClothModel>(std::move(model).value());

  PendulumScene scene;
  scene.m_length = settings.length;
  WorldSettings worldSettings;
  worldSettings.threadCount = 1;
  worldSettings.gravity = Vec3(0, -kGravity, 0);
  scene.m_world = std::make_unique<World>(worldSettings);
  ClothSettings cloth;
  cloth.forceModel = ForceModel::MassSpring;
  cloth.springs.structuralStiffness = settings.springStiffness;
  cloth.springs.structuralDamping = 0;
  cloth.material.airDrag = 0;
  cloth.material.arealDensity = 3.0 / shared->totalArea();  // 1 kg per vertex
  cloth.pinnedVertices = {0, 1};
  cloth.selfCollision = false;
  cloth.sleep.enabled = false;
  cloth.solver = settings.solver;
  Result<ClothId> id = scene.m_world->createCloth(shared, cloth);
  if (!id.ok()) return id.error();
  scene.m_cloth = id.value();
  return scene;
}

Real PendulumScene::angle() const {
  const Vec3 bob = m_world->positions(m_cloth).value()[2];
  return std::atan2(bob.z(), -bob.y());
}

Real PendulumScene::frequency() const { return std::sqrt(kGravity / m_length); }

}  // namespace weft

namespace weft {

std::complex<Real> PendulumScene::growthFactor(IntegratorKind kind, Real omegaH) {
  const std::complex<Real> z(0, omegaH);
  if (kind == IntegratorKind::Bdf2) return (2.0 + std::sqrt(1.0 + 2.0 * z)) / (3.0 - 2.0 * z);
  if (kind == IntegratorKind::ImplicitEuler) return 1.0 / (1.0 - z);
  return {std::nan(""), std::nan("")};  // the explicit methods are not covered
}

}  // namespace weft
