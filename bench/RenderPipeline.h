// RenderPipeline: draws simulated frames on a thread of its own, as a game's render thread would.
//
// The simulation thread publishes a snapshot (positions and normals copied out of the engine, so
// the engine's state and the drawn state are two buffers) and goes on with the next frame while this thread draws and reads back the previous
// one: simulation of frame k+1 overlaps rendering of frame k, so two cores are both used. With
// overlap off, publish() waits for the frame to be drawn before returning, which gives the
// sequential baseline the overlap is measured against.
//
// The EGL context is created and used only on the render thread: an OpenGL context is current on
// one thread at a time, and keeping it there avoids handing it back and forth every frame.
#pragma once

#include <weft/engine/RenderView.h>
#include <weft/render/ClothRenderer.h>
#include <weft/render/Image.h>

#include <condition_variable>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace weft {

class RenderPipeline {
 public:
  /// Starts the render thread and creates the context there; the error says what is missing.
  static Result<std::unique_ptr<RenderPipeline>> start(const RenderSettings& settings,
                                                       std::vector<ColliderPrimitive> colliders,
                                                       std::vector<unsigned> captureFrames,
                                                       bool overlap);
  ~RenderPipeline();

  /// Hands frame `frame` to the render thread (copying the view), waiting first until the
  /// previous frame has been drawn. Returns the ms spent waiting.
  double publish(unsigned frame, const ClothRenderView& view,
                 std::span<const ColliderPrimitive> movingColliders = {});
  /// Waits until every published frame has been drawn.
  void drain();

  /// Render and readback ms of each drawn frame, by frame number.
  const std::map<unsigned, FrameTiming>& timings() const { return m_timings; }
  /// Pictures kept for capture, by frame number.
  const std::map<unsigned, Image>& captured() const { return m_captured; }
  /// First render error, empty when none.
  const std::string& error() const { return m_error; }
  /// GL_RENDERER of the context (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  const std::string& rendererName() const { return m_rendererName; }

 private:
  RenderPipeline() = default;
  void run(RenderSettings settings);

  struct Snapshot {
    Vec3Array positions, normals;
    std::vector<Index> indices;
    std::vector<ColliderPrimitive> colliders;  // the static ones, then this frame's moving ones
    unsigned frame = 0;
  };
  Snapshot m_snapshot;
  std::vector<ColliderPrimitive> m_colliders;
  std::vector<unsigned> m_captureFrames;
  bool m_overlap = true;

  std::thread m_thread;
  std::mutex m_mutex;
  std::condition_variable m_changed;
  bool m_pending = false;    // a snapshot is waiting to be drawn
  bool m_busy = false;       // the render thread is drawing
  bool m_stopping = false;
  bool m_started = false;    // context creation finished (successfully or not)

  std::map<unsigned, FrameTiming> m_timings;
  std::map<unsigned, Image> m_captured;
  std::string m_error;
  std::string m_rendererName;
};

}  // namespace weft
