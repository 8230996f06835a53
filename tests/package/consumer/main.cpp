// The package consumer: what a game does first with Weft. An 11×9 cloth hangs from its pinned
// top row for 30 frames; prints the state hash and the largest strain, and exits non-zero when
// an API call fails, a frame is rolled back or refused, or any position is non-finite.
#include <weft/Weft.h>
#if WEFT_CONSUMER_RENDER
#include <weft/render/Png.h>
#endif

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace {

int fail(const char* what, const weft::Error& error) {
  std::fprintf(stderr, "weft-consumer: %s: %s\n", what, error.message.c_str());
  return 1;
}

}  // namespace

int main() {
  weft::GridSettings grid;
  grid.columns = 11;
  grid.rows = 9;
  grid.width = 1.0;   // m
  grid.height = 0.8;  // m
  grid.origin = weft::Vec3(-0.5, 1.0, 0.0);
  auto model = weft::ClothModel::grid(grid);
  if (!model) return fail("ClothModel::grid", model.error());
  auto shared = std::make_shared<const weft::ClothModel>(std::move(model).value());

  // Rows grow along +y from the origin, so the top row is the last one.
  weft::ClothSettings settings;
  for (weft::Index column = 0; column < grid.columns; ++column) {
    settings.pinnedVertices.push_back((grid.rows - 1) * grid.columns + column);
  }

  weft::World world;
  auto cloth = world.createCloth(shared, settings);
  if (!cloth) return fail("World::createCloth", cloth.error());

  constexpr int kFrames = 30;
  double maxStrain = 0;
  for (int frame = 0; frame < kFrames; ++frame) {
    const weft::StepStatus status = world.step(1.0 / 60.0);
    if (weft::hasFlag(status, weft::StepStatus::RolledBack) ||
        weft::hasFlag(status, weft::StepStatus::InvalidInput)) {
      std::fprintf(stderr, "weft-consumer: frame %d: %s\n", frame, weft::describe(status).c_str());
      return 1;
    }
    maxStrain = std::max(maxStrain, world.stats().maxStrain);
  }

  auto positions = world.positions(cloth.value());
  if (!positions) return fail("World::positions", positions.error());
  const bool finite = std::all_of(positions->begin(), positions->end(),
                                  [](const weft::Vec3& x) { return weft::isFinite(x); });
  if (!finite || !std::isfinite(maxStrain)) {
    std::fprintf(stderr, "weft-consumer: non-finite state after %d frames\n", kFrames);
    return 1;
  }

#if WEFT_CONSUMER_RENDER
  // No GL context here (the test may run without one): a call into libpng through weft::render
  // is enough to prove the static library and its private dependencies link.
  if (weft::readPng("/nonexistent/weft-consumer.png").ok()) {
    std::fprintf(stderr, "weft-consumer: readPng of a missing file succeeded\n");
    return 1;
  }
  std::printf("weft-consumer: weft::render linked\n");
#endif

  std::printf("weft-consumer: %d frames, %u vertices, state hash %016" PRIx64 ", max strain %.6f\n",
              kFrames, static_cast<unsigned>(shared->vertexCount()), world.stateHash(), maxStrain);
  std::printf("weft-consumer: ok\n");
  return 0;
}
