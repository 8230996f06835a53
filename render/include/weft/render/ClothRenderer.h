// ClothRenderer: draws cloths (from ClothRenderView) and collider primitives into an EglContext.
//
// Design note. The renderer follows the simulation, so it is built for "same topology, new
// positions every frame":
//   * One vertex buffer (interleaved float position + normal) and one index buffer hold every
//     cloth of the frame; they grow when needed and are otherwise refilled with glBufferSubData.
//     The double → float conversion (and the normals, when a view has none) goes into CPU
//     buffers kept between frames, so a steady frame allocates nothing.
//   * Collider primitives are unit meshes (sphere, cylinder, quad, cube) built once and placed with
//     a model matrix; a capsule is a cylinder and two spheres.
//   * One shader pair, compiled once: two-sided Lambert + ambient. Back faces (gl_FrontFacing
//     false) use the flipped normal and their own colour, so folds show which side is out.
//     The wireframe overlay redraws the cloth as lines; the shaded pass is pushed back with
//     glPolygonOffset so lines do not z-fight.
//   * Timing is wall time around the GL calls with a glFinish before the clock stops: GL is
//     asynchronous, and without the finish the rasteriser's work would be billed to readback.
// Rejected: per-cloth buffers (more binds for nothing at these sizes), a geometry-shader
// wireframe (one more programmable stage on every triangle, for an overlay that is off by
// default), instancing (a handful of colliders), MSAA (about 4× the cost on llvmpipe).
#pragma once

#include <weft/Result.h>
#include <weft/engine/RenderView.h>
#include <weft/render/ColliderPrimitive.h>
#include <weft/render/EglContext.h>
#include <weft/render/Image.h>
#include <weft/render/RenderSettings.h>

#include <memory>
#include <span>

namespace weft {

/// What one frame shows.
struct RenderScene {
  std::span<const ClothRenderView> cloths;         ///< drawn with the cloth colours of RenderSettings
  std::span<const ColliderPrimitive> colliders;    ///< drawn when RenderSettings::drawColliders
};

/// Draws cloths and colliders with OpenGL into an EglContext's framebuffer.
class ClothRenderer {
 public:
  /// GL objects and CPU staging buffers; defined in src/, never touched by callers.
  class Impl;

  /// Compiles the shaders and builds the primitive meshes in context (made current here).
  /// context must outlive the renderer; it may be moved (the renderer keeps its internals).
  /// Errors carry the shader compiler's log.
  static Result<ClothRenderer> create(EglContext& context, const RenderSettings& settings = {});

  /// Move-only; a moved-from renderer may only be destroyed or assigned to.
  ClothRenderer(ClothRenderer&&) noexcept;
  /// Move-only; releases this renderer's GL objects first.
  ClothRenderer& operator=(ClothRenderer&&) noexcept;
  ClothRenderer(const ClothRenderer&) = delete;
  ClothRenderer& operator=(const ClothRenderer&) = delete;
  /// Deletes the GL objects (makes the context current first).
  ~ClothRenderer();

  /// Replaces the settings; the error says which field is out of range (settings unchanged).
  Status setSettings(const RenderSettings& settings);
  /// The settings in use.
  const RenderSettings& settings() const;

  /// Draws scene. The error names the cloth and the bad index or size (nothing drawn).
  Result<FrameTiming> renderFrame(const RenderScene& scene);
  /// Draws scene and reads the picture back into image (top-down RGBA8, allocation reused).
  Result<FrameTiming> renderFrame(const RenderScene& scene, Image& image);

  /// Timing of the last successful renderFrame().
  const FrameTiming& lastTiming() const;

 private:
  explicit ClothRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> m_impl;
};

}  // namespace weft
