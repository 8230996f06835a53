#include <weft/scenes/FreeDrape.h>

#include <cmath>
#include <string>

namespace weft {

Result<FreeDrapeScene> FreeDrapeScene::create(const FreeDrapeSettings& settings) {
  if (!(settings.size > 0) || !std::isfinite(settings.size)) {
    return Error{"free drape size must be a positive number of metres"};
  }
  if (settings.verticesPerSide < 2) {
    return Error{"free drape verticesPerSide must be at least 2, got " +
                 std::to_string(settings.verticesPerSide)};
  }
  if (!std::isfinite(settings.releaseAngle)) {
    return Error{"free drape releaseAngle must be finite (radians from the vertical)"};
  }
  // Rows grow from the bottom edge up to the pinned top edge at y = 0.
  const Real c = std::cos(settings.releaseAngle), s = std::sin(settings.releaseAngle);
  GridSettings grid;
  grid.columns = grid.rows = settings.verticesPerSide;
  grid.width = grid.height = settings.size;
  grid.widthAxis = Vec3(1, 0, 0);
  grid.heightAxis = Vec3(0, c, -s);
  grid.origin = Vec3(-0.5 * settings.size, -settings.size * c, settings.size * s);
  Result<ClothModel> model = ClothModel::grid(grid);
  if (!model.ok()) return model.error();

  FreeDrapeScene scene;
  scene.m_model = std::make_shared<const ClothModel>(std::move(model).value());
  WorldSettings worldSettings;
  worldSettings.threadCount = settings.threadCount;
  scene.m_world = std::make_unique<World>(worldSettings);
  ClothSettings cloth;
  cloth.material = settings.material;
  cloth.solver = settings.solver;
  cloth.selfCollision = false;  // nothing to touch: the motion stays smooth
  cloth.sleep.enabled = false;
  for (Index column = 0; column < grid.columns; ++column) {
    cloth.pinnedVertices.push_back((grid.rows - 1) * grid.columns + column);
  }
  Result<ClothId> id = scene.m_world->createCloth(scene.m_model, cloth);
  if (!id.ok()) return id.error();
  scene.m_cloth = id.value();
  return scene;
}

}  // namespace weft
