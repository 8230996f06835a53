// LoadScene: run a JSON scene file (format: scenes/data/README.md) from a program. The file is
// parsed and validated in one pass (every problem is reported at its JSON path, with the fix);
// weft::ScriptedScene builds the World and plays the file's pin, collider and wind scripts frame
// by frame. Here the program then reads the world as any game would.
//
//   weft-example-load-scene SCENE.json [frames = the file's run length]
#include <weft/scenes/ScriptedScene.h>

#include <cinttypes>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.json [frames]\n", argv[0]);
    return 2;
  }
  auto description = weft::loadSceneFile(argv[1]);
  if (!description) {
    // One "path: message" line per problem, e.g. "/cloths/0/material/arealDensity: is -0.15 but
    // must be greater than 0 (kg/m²)".
    std::fprintf(stderr, "load-scene: %s\n", description.error().message.c_str());
    return 1;
  }
  const long frames = argc > 2 ? std::atol(argv[2]) : long(description->frames);
  if (frames <= 0) {
    std::fprintf(stderr, "load-scene: frames must be a positive number\n");
    return 2;
  }
  std::printf("load-scene: '%s', %zu cloth(s), %zu collider(s), %ld frames of %.4f s\n",
              description->name.c_str(), description->cloths.size(), description->colliders.size(),
              frames, description->frameDt);

  auto scene = weft::ScriptedScene::create(std::move(description).value());
  if (!scene) {
    std::fprintf(stderr, "load-scene: %s\n", scene.error().message.c_str());
    return 1;
  }
  for (long frame = 1; frame <= frames; ++frame) {
    const weft::StepStatus status = scene->stepFrame();
    if (weft::hasFlag(status, weft::StepStatus::RolledBack) ||
        weft::hasFlag(status, weft::StepStatus::InvalidInput)) {
      std::fprintf(stderr, "load-scene: frame %ld: %s\n", frame, weft::describe(status).c_str());
      return 1;
    }
  }

  const weft::World& world = scene->world();
  for (std::size_t k = 0; k < scene->clothCount(); ++k) {
    auto positions = world.positions(scene->cloth(k));
    if (!positions) return 1;
    weft::Vec3 lowest = positions->front();
    for (const weft::Vec3& x : positions.value()) {
      if (x.y() < lowest.y()) lowest = x;
    }
    std::printf("  %-12s %zu vertices, lowest point (%+.3f, %+.3f, %+.3f) m, %s\n",
                scene->description().cloths[k].name.c_str(), positions->size(), lowest.x(),
                lowest.y(), lowest.z(), world.isSleeping(scene->cloth(k)).value() ? "asleep" : "awake");
  }
  std::printf("load-scene: ok, %.2f s simulated, max strain %.4f, state hash %016" PRIx64 "\n",
              world.time(), world.stats().maxStrain, world.stateHash());
  return 0;
}
