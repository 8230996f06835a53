// ImageSequenceWriter: a bounded queue in front of one encoder thread (see the header for why).
// Frames are encoded in the order they were queued, so file numbers follow write() calls.
#include <weft/render/ImageSequenceWriter.h>
#include <weft/render/Png.h>

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace weft {

class ImageSequenceWriter::Impl {
 public:
  std::string dir;
  ImageSequenceSettings settings;
  int queued = 0;  // frames handed to write(); also the number of the next frame

  std::mutex mutex;
  std::condition_variable changed;
  struct Job {
    int index;
    Image image;
  };
  std::deque<Job> pending;
  std::vector<Image> spare;  // images already encoded, kept to reuse their allocation
  bool busy = false;         // the worker holds a job outside the queue
  bool stopping = false;
  Error firstError;
  bool failed = false;
  std::thread worker;

  std::string pathOf(int index) const {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", index);
    return (std::filesystem::path(dir) / name).string();
  }

  void run() {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return stopping || !pending.empty(); });
      if (pending.empty()) return;  // stopping and drained
      Job job = std::move(pending.front());
      pending.pop_front();
      busy = true;
      changed.notify_all();  // room in the queue
      lock.unlock();
      Status status = writePng(pathOf(job.index), job.image, PngCompression::kFast);
      lock.lock();
      busy = false;
      if (!status && !failed) {
        failed = true;
        firstError = status.error();
      }
      spare.push_back(std::move(job.image));
      changed.notify_all();
    }
  }

  Status write(const Image& image) {
    std::unique_lock lock(mutex);
    if (failed) return firstError;
    const auto capacity = static_cast<std::size_t>(std::max(settings.queueCapacity, 1));
    changed.wait(lock, [&] { return pending.size() < capacity || failed; });
    if (failed) return firstError;
    Image copy;
    if (!spare.empty()) {
      copy = std::move(spare.back());
      spare.pop_back();
    }
    copy.width = image.width;
    copy.height = image.height;
    copy.rgba.assign(image.rgba.begin(), image.rgba.end());
    pending.push_back({settings.firstIndex + queued, std::move(copy)});
    ++queued;
    changed.notify_all();
    return {};
  }

  Status drain() {
    std::unique_lock lock(mutex);
    changed.wait(lock, [&] { return (pending.empty() && !busy) || !worker.joinable(); });
    if (failed) return firstError;
    return {};
  }

  void stop() {
    {
      std::lock_guard lock(mutex);
      stopping = true;
    }
    changed.notify_all();
    if (worker.joinable()) worker.join();
  }

  ~Impl() { stop(); }
};

Result<ImageSequenceWriter> ImageSequenceWriter::open(const std::string& dir, const ImageSequenceSettings& settings) {
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error || !std::filesystem::is_directory(dir)) {
    return Error{"ImageSequenceWriter: cannot create directory '" + dir + "': " +
                 (error ? error.message() : std::string("a file of that name exists"))};
  }
  if (settings.firstIndex < 0) {
    return Error{"ImageSequenceSettings::firstIndex must be ≥ 0 (got " + std::to_string(settings.firstIndex) + ")"};
  }
  auto impl = std::make_unique<Impl>();
  impl->dir = dir;
  impl->settings = settings;
  impl->worker = std::thread([raw = impl.get()] { raw->run(); });
  return ImageSequenceWriter(std::move(impl));
}

ImageSequenceWriter::ImageSequenceWriter(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
ImageSequenceWriter::ImageSequenceWriter(ImageSequenceWriter&&) noexcept = default;
ImageSequenceWriter& ImageSequenceWriter::operator=(ImageSequenceWriter&&) noexcept = default;
ImageSequenceWriter::~ImageSequenceWriter() = default;

Status ImageSequenceWriter::write(const Image& image) {
  if (image.empty()) return Error{"ImageSequenceWriter::write: empty image (frame " + std::to_string(m_impl->queued) + ")"};
  return m_impl->write(image);
}

Status ImageSequenceWriter::finish() { return m_impl->drain(); }

int ImageSequenceWriter::framesQueued() const { return m_impl->queued; }

std::string ImageSequenceWriter::framePath(int index) const { return m_impl->pathOf(index); }

}  // namespace weft
