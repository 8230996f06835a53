// SceneDrawing: draws a ScriptedScene with weft::render (headless EGL) for `weft run --render`,
// on the calling thread, and hands each picture to an optional PNG sequence writer.
//
// Colliders are drawn as the renderer's primitives (sphere, plane patch, capsule, box) posed where
// the world has them this frame; triangle-mesh colliders have no primitive and are not drawn.
#pragma once

#include <weft/Result.h>
#include <weft/scenes/ScriptedScene.h>

#include <memory>
#include <string>

namespace weft {

/// Renders scene frames; only built with weft::render.
class SceneDrawing {
 public:
  /// Creates the context and renderer at width × height with the scene's camera; when
  /// captureDirectory is not empty, frames passed with capture = true go there as PNGs.
  static Result<std::unique_ptr<SceneDrawing>> create(const ScriptedScene& scene, int width,
                                                      int height,
                                                      const std::string& captureDirectory);
  ~SceneDrawing();

  /// Draws the scene as it is now (and queues the picture for capture). Returns the ms spent
  /// drawing and reading back.
  Result<double> draw(const ScriptedScene& scene, bool capture);
  /// Waits for captured frames to be written; the error names the failing file.
  Status finish();
  /// GL_RENDERER of the context.
  std::string rendererName() const;
  /// Triangle-mesh colliders that are not drawn.
  int undrawnColliders() const;

 private:
  struct Impl;
  explicit SceneDrawing(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> m_impl;
};

}  // namespace weft
