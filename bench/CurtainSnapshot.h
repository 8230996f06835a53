// The curtain a few frames into its script, its positions and velocities copied out: the state
// the stage benches (assembly, PCG) assemble and solve from, the same in each.
#pragma once

#include <weft/scenes/Curtain.h>

#include <memory>

namespace weft {

struct CurtainSnapshot {
  CurtainSettings settings;
  std::unique_ptr<CurtainScene> scene;
  Vec3Array x, v;  // m and m/s, per vertex
};

/// The curtain at refinement `size` after `frames` frames of its script.
inline CurtainSnapshot curtainSnapshot(Index size, int frames = 12) {
  CurtainSnapshot snapshot;
  snapshot.settings.size = size;
  snapshot.scene = std::make_unique<CurtainScene>(CurtainScene::create(snapshot.settings).value());
  for (int frame = 0; frame < frames; ++frame) snapshot.scene->stepFrame();
  const auto positions = snapshot.scene->world().positions(snapshot.scene->cloth()).value();
  const auto velocities = snapshot.scene->world().velocities(snapshot.scene->cloth()).value();
  snapshot.x.assign(positions.begin(), positions.end());
  snapshot.v.assign(velocities.begin(), velocities.end());
  return snapshot;
}

}  // namespace weft
