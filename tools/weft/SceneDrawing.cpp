#include "SceneDrawing.h"

#include <weft/render/ClothRenderer.h>
#include <weft/render/EglContext.h>
#include <weft/render/ImageSequenceWriter.h>

#include <chrono>
#include <optional>
#include <type_traits>
#include <variant>

namespace weft {

struct SceneDrawing::Impl {
  std::optional<EglContext> context;
  std::optional<ClothRenderer> renderer;
  std::optional<ImageSequenceWriter> capture;
  Image image;
  std::vector<ClothRenderView> views;          // reused every frame
  std::vector<ColliderPrimitive> primitives;   // reused every frame
  int undrawn = 0;
};

SceneDrawing::SceneDrawing(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
SceneDrawing::~SceneDrawing() = default;

Result<std::unique_ptr<SceneDrawing>> SceneDrawing::create(const ScriptedScene& scene, int width,
                                                           int height,
                                                           const std::string& captureDirectory) {
  auto impl = std::make_unique<Impl>();
  ContextSettings contextSettings;
  contextSettings.width = width;
  contextSettings.height = height;
  Result<EglContext> context = EglContext::create(contextSettings);
  if (!context.ok()) return context.error();
  impl->context.emplace(std::move(context).value());

  const SceneCamera& camera = scene.description().camera;
  RenderSettings settings;
  settings.width = width;
  settings.height = height;
  settings.camera.eye = camera.eye;
  settings.camera.target = camera.target;
  settings.camera.up = camera.up;
  settings.camera.verticalFovDegrees = camera.verticalFovDegrees;
  Result<ClothRenderer> renderer = ClothRenderer::create(*impl->context, settings);
  if (!renderer.ok()) return renderer.error();
  impl->renderer.emplace(std::move(renderer).value());

  if (!captureDirectory.empty()) {
    Result<ImageSequenceWriter> writer = ImageSequenceWriter::open(captureDirectory);
    if (!writer.ok()) return writer.error();
    impl->capture.emplace(std::move(writer).value());
  }
  for (const ColliderDescription& collider : scene.description().colliders) {
    impl->undrawn += std::holds_alternative<TriangleMeshShape>(collider.shape);
  }
  return std::unique_ptr<SceneDrawing>(new SceneDrawing(std::move(impl)));
}

Result<double> SceneDrawing::draw(const ScriptedScene& scene, bool capture) {
  Impl& impl = *m_impl;
  impl.views.clear();
  for (std::size_t k = 0; k < scene.clothCount(); ++k) {
    Result<ClothRenderView> view = scene.world().renderView(scene.cloth(k));
    if (!view.ok()) return view.error();
    impl.views.push_back(view.value());
  }
  impl.primitives.clear();
  for (std::size_t k = 0; k < scene.colliderCount(); ++k) {
    Result<const Shape*> shape = scene.world().collider(scene.collider(k));
    if (!shape.ok()) return shape.error();
    std::visit(
        [&](const auto& s) {
          using T = std::decay_t<decltype(s)>;
          const Pose& pose = s.motion().pose;
          // Drawn 2 % inside the true surface, so cloth resting on it is not hidden by it.
          if constexpr (std::is_same_v<T, Sphere>) {
            impl.primitives.push_back(SpherePrimitive{pose.position, s.radius() * 0.98});
          } else if constexpr (std::is_same_v<T, Plane>) {
            impl.primitives.push_back(PlanePrimitive{pose.position, s.normal(), 3.0});
          } else if constexpr (std::is_same_v<T, Capsule>) {
            const Vec3 axis = pose.directionToWorld(Vec3(0, s.halfLength(), 0));
            impl.primitives.push_back(CapsulePrimitive{pose.position - axis, pose.position + axis,
                                                       s.radius() * 0.98});
          } else if constexpr (std::is_same_v<T, Box>) {
            impl.primitives.push_back(BoxPrimitive{pose.position, s.halfExtents() * 0.98,
                                                   pose.rotation.toRotationMatrix()});
          }
        },
        *shape.value());
  }
  RenderScene frame{impl.views, impl.primitives};
  Result<FrameTiming> timing = capture && impl.capture ? impl.renderer->renderFrame(frame, impl.image)
                                                       : impl.renderer->renderFrame(frame);
  if (!timing.ok()) return timing.error();
  if (capture && impl.capture) {
    Status written = impl.capture->write(impl.image);
    if (!written.ok()) return written.error();
  }
  return timing->renderMs + timing->readbackMs;
}

Status SceneDrawing::finish() {
  if (!m_impl->capture) return Status::success();
  return m_impl->capture->finish();
}

std::string SceneDrawing::rendererName() const { return m_impl->context->renderer(); }

int SceneDrawing::undrawnColliders() const { return m_impl->undrawn; }

}  // namespace weft
