#include "RenderPipeline.h"

#include <weft/render/EglContext.h>
#include <weft/threading/Profiler.h>

#include <algorithm>
#include <chrono>

namespace weft {

Result<std::unique_ptr<RenderPipeline>> RenderPipeline::start(const RenderSettings& settings,
                                                              std::vector<ColliderPrimitive> colliders,
                                                              std::vector<unsigned> captureFrames,
                                                              bool overlap) {
  std::unique_ptr<RenderPipeline> pipeline(new RenderPipeline());
  pipeline->m_colliders = std::move(colliders);
  pipeline->m_captureFrames = std::move(captureFrames);
  pipeline->m_overlap = overlap;
  RenderPipeline* self = pipeline.get();
  self->m_thread = std::thread([self, settings] { self->run(settings); });
  std::unique_lock lock(self->m_mutex);
  self->m_changed.wait(lock, [self] { return self->m_started; });
  if (!self->m_error.empty()) {
    Error error{self->m_error};
    lock.unlock();
    return error;  // the destructor joins the thread, which has already returned
  }
  return pipeline;
}

RenderPipeline::~RenderPipeline() {
  {
    std::lock_guard lock(m_mutex);
    m_stopping = true;
  }
  m_changed.notify_all();
  if (m_thread.joinable()) m_thread.join();
}

double RenderPipeline::publish(unsigned frame, const ClothRenderView& view,
                               std::span<const ColliderPrimitive> movingColliders) {
  const auto start = std::chrono::steady_clock::now();
  std::unique_lock lock(m_mutex);
  // One frame in flight at most: wait until the previous one has been taken and drawn.
  m_changed.wait(lock, [this] { return (!m_pending && !m_busy) || !m_error.empty(); });
  const double waitedMs =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!m_error.empty()) return waitedMs;
  Snapshot& snapshot = m_snapshot;
  snapshot.positions.assign(view.positions.begin(), view.positions.end());
  snapshot.normals.assign(view.normals.begin(), view.normals.end());
  if (snapshot.indices.size() != view.indices.size()) {
    snapshot.indices.assign(view.indices.begin(), view.indices.end());
  }
  snapshot.colliders.assign(m_colliders.begin(), m_colliders.end());
  snapshot.colliders.insert(snapshot.colliders.end(), movingColliders.begin(), movingColliders.end());
  snapshot.frame = frame;
  m_pending = true;
  lock.unlock();
  m_changed.notify_all();
  if (!m_overlap) drain();
  return waitedMs;
}

void RenderPipeline::drain() {
  std::unique_lock lock(m_mutex);
  m_changed.wait(lock, [this] { return (!m_pending && !m_busy) || !m_error.empty(); });
}

void RenderPipeline::run(RenderSettings settings) {
  auto fail = [this](const std::string& message) {
    std::lock_guard lock(m_mutex);
    if (m_error.empty()) m_error = message;
    m_started = true;
    m_changed.notify_all();
  };
  Result<EglContext> context = EglContext::create({settings.width, settings.height});
  if (!context.ok()) return fail(context.error().message);
  Result<ClothRenderer> renderer = ClothRenderer::create(context.value(), settings);
  if (!renderer.ok()) return fail(renderer.error().message);
  {
    std::lock_guard lock(m_mutex);
    m_rendererName = context->renderer();
    m_started = true;
  }
  m_changed.notify_all();

  Profiler::instance().registerThisThread("render");
  Image image;
  for (;;) {
    std::unique_lock lock(m_mutex);
    m_changed.wait(lock, [this] { return m_pending || m_stopping; });
    if (!m_pending) return;  // stopping with nothing left to draw
    // publish() does not touch the snapshot again until this frame is drawn (m_busy).
    const Snapshot& snapshot = m_snapshot;
    m_pending = false;
    m_busy = true;
    lock.unlock();

    const ClothRenderView view{snapshot.positions, snapshot.normals, snapshot.indices};
    const RenderScene scene{std::span<const ClothRenderView>(&view, 1), snapshot.colliders};
    Result<FrameTiming> timing = [&] {
      WEFT_PROFILE_ZONE("render");
      return renderer->renderFrame(scene, image);
    }();

    lock.lock();
    m_busy = false;
    if (!timing.ok()) {
      if (m_error.empty()) m_error = timing.error().message;
    } else {
      m_timings[snapshot.frame] = timing.value();
      if (std::find(m_captureFrames.begin(), m_captureFrames.end(), snapshot.frame) !=
          m_captureFrames.end()) {
        m_captured[snapshot.frame] = image;  // encoded after the run, off the frame loop
      }
    }
    lock.unlock();
    m_changed.notify_all();
  }
}

}  // namespace weft
