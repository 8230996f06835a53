// VideoWriter: pipes raw RGBA frames to an ffmpeg process that encodes H.264 (yuv420p) MP4.
//
// ffmpeg is optional. When it is not on PATH, open() still succeeds with a disabled writer whose
// notice() reads "ffmpeg not found; skipping video (apt-get install ffmpeg)", and write() does
// nothing: a missing encoder must not fail a simulation run. Rejected: linking libavcodec (a large
// dependency for an optional feature) and writing our own encoder.
#pragma once

#include <weft/Result.h>
#include <weft/render/Image.h>

#include <memory>
#include <string>

namespace weft {

/// Settings of a video.
struct VideoSettings {
  int width = 1280;     ///< pixels; every frame must have this size (even numbers for yuv420p)
  int height = 720;     ///< pixels
  double fps = 60.0;    ///< frames per second of playback
  std::string ffmpeg = "ffmpeg";  ///< program name (searched on PATH) or path of the ffmpeg binary
};

/// Feeds frames to ffmpeg through a pipe; a no-op when ffmpeg is missing.
class VideoWriter {
 public:
  /// Queue, thread or pipe state; defined in src/, never touched by callers.
  class Impl;

  /// Starts ffmpeg writing path (overwritten). Errors: bad size or fps, or ffmpeg failing to start.
  /// A missing ffmpeg is not an error: see enabled() and notice().
  static Result<VideoWriter> open(const std::string& path, const VideoSettings& settings = {});

  /// Move-only; a moved-from writer may only be destroyed or assigned to.
  VideoWriter(VideoWriter&&) noexcept;
  /// Move-only; finishes this writer first.
  VideoWriter& operator=(VideoWriter&&) noexcept;
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;
  /// Closes the pipe and waits for ffmpeg (errors are dropped; call finish() to see them).
  ~VideoWriter();

  /// True when frames reach ffmpeg; false when ffmpeg was not found.
  bool enabled() const;
  /// Why the writer is disabled (empty when enabled).
  const std::string& notice() const;
  /// Sends one frame (must match the size given to open()); ok and ignored when disabled.
  Status write(const Image& image);
  /// Closes the pipe and waits for ffmpeg; the error carries ffmpeg's exit status.
  Status finish();
  /// Frames sent so far.
  int framesWritten() const;

 private:
  explicit VideoWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> m_impl;
};

}  // namespace weft
