// ImageSequenceWriter: frames to dir/frame_00000.png, frame_00001.png, ... on a background thread.
//
// PNG encoding of a 720p frame costs more than a frame (40–150 ms), so write() only copies the
// image into a small queue and returns; one worker thread encodes in order. When the queue is full
// write() waits (back-pressure beats unbounded memory). Errors are kept and returned by the next
// write() and by finish(): a full disk stops the capture, not the simulation.
#pragma once

#include <weft/Result.h>
#include <weft/render/Image.h>

#include <memory>
#include <string>

namespace weft {

/// Settings of an image sequence.
struct ImageSequenceSettings {
  int queueCapacity = 4;  ///< frames waiting for the encoder before write() blocks; raising it costs 4·W·H bytes each
  int firstIndex = 0;     ///< number of the first file (frame_%05d.png)
};

/// Writes numbered PNG frames into a directory, encoding off the calling thread.
class ImageSequenceWriter {
 public:
  /// Queue, thread or pipe state; defined in src/, never touched by callers.
  class Impl;

  /// Creates dir (and parents) if needed; the error names the directory.
  static Result<ImageSequenceWriter> open(const std::string& dir, const ImageSequenceSettings& settings = {});

  /// Move-only; a moved-from writer may only be destroyed or assigned to.
  ImageSequenceWriter(ImageSequenceWriter&&) noexcept;
  /// Move-only; finishes this writer first.
  ImageSequenceWriter& operator=(ImageSequenceWriter&&) noexcept;
  ImageSequenceWriter(const ImageSequenceWriter&) = delete;
  ImageSequenceWriter& operator=(const ImageSequenceWriter&) = delete;
  /// Finishes the queued frames (errors are dropped; call finish() to see them).
  ~ImageSequenceWriter();

  /// Queues a copy of image as the next frame; returns an earlier frame's error, if any.
  Status write(const Image& image);
  /// Waits until every queued frame is on disk; returns the first error, if any.
  Status finish();
  /// Number of frames handed to write() so far.
  int framesQueued() const;
  /// Path the frame with this index is written to.
  std::string framePath(int index) const;

 private:
  explicit ImageSequenceWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> m_impl;
};

}  // namespace weft
