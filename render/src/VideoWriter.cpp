// VideoWriter: raw RGBA frames into `ffmpeg -f rawvideo ... -i -` through popen.
//
// A pipe whose reader died raises SIGPIPE, which by default kills the whole process. We do not
// change the process's signal disposition (that belongs to the application); instead SIGPIPE is
// blocked on the writing thread for the duration of fwrite, and a SIGPIPE that arrived meanwhile
// is consumed before unblocking, so a crashed ffmpeg becomes an EPIPE error from write().
#include <weft/render/VideoWriter.h>

#include <pthread.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

namespace weft {
namespace {

constexpr const char* kMissingNotice = "ffmpeg not found; skipping video (apt-get install ffmpeg)";

bool isExecutable(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::is_regular_file(path, error) && ::access(path.c_str(), X_OK) == 0;
}

// Resolves program the way a shell would: as a path when it has a slash, else along PATH.
std::string findProgram(const std::string& program) {
  if (program.find('/') != std::string::npos) return isExecutable(program) ? program : std::string();
  const char* pathVariable = std::getenv("PATH");
  if (pathVariable == nullptr) return {};
  std::istringstream directories(pathVariable);
  std::string directory;
  while (std::getline(directories, directory, ':')) {
    const std::filesystem::path candidate = std::filesystem::path(directory.empty() ? "." : directory) / program;
    if (isExecutable(candidate)) return candidate.string();
  }
  return {};
}

// Single-quotes text for /bin/sh: ' becomes '\''.
std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// Blocks SIGPIPE on this thread for its lifetime; swallows one that arrived meanwhile.
class ScopedSigpipeBlock {
 public:
  ScopedSigpipeBlock() {
    sigemptyset(&m_pipe);
    sigaddset(&m_pipe, SIGPIPE);
    sigset_t pending;
    sigpending(&pending);
    m_alreadyPending = sigismember(&pending, SIGPIPE) == 1;
    pthread_sigmask(SIG_BLOCK, &m_pipe, &m_previous);
  }
  ~ScopedSigpipeBlock() {
    if (!m_alreadyPending) {
      sigset_t pending;
      sigpending(&pending);
      if (sigismember(&pending, SIGPIPE) == 1) {
        const timespec noWait{0, 0};
        sigtimedwait(&m_pipe, nullptr, &noWait);
      }
    }
    pthread_sigmask(SIG_SETMASK, &m_previous, nullptr);
  }
  ScopedSigpipeBlock(const ScopedSigpipeBlock&) = delete;
  ScopedSigpipeBlock& operator=(const ScopedSigpipeBlock&) = delete;

 private:
  sigset_t m_pipe;
  sigset_t m_previous;
  bool m_alreadyPending = false;
};

}  // namespace

class VideoWriter::Impl {
 public:
  std::string path;
  VideoSettings settings;
  std::string notice;
  std::FILE* pipe = nullptr;
  int frames = 0;
  bool failed = false;

  Status close() {
    if (pipe == nullptr) return {};
    int status = 0;
    {
      ScopedSigpipeBlock block;
      status = pclose(pipe);
    }
    pipe = nullptr;
    if (status == -1) return Error{"VideoWriter: could not wait for ffmpeg writing '" + path + "': " + std::strerror(errno)};
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      return Error{"VideoWriter: ffmpeg failed writing '" + path + "' (exit status " +
                   std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + "); its messages are on stderr"};
    }
    return {};
  }

  ~Impl() { (void)close(); }
};

Result<VideoWriter> VideoWriter::open(const std::string& path, const VideoSettings& settings) {
  if (settings.width <= 0 || settings.height <= 0 || settings.width % 2 != 0 || settings.height % 2 != 0) {
    return Error{"VideoSettings: width and height must be positive and even for yuv420p (got " +
                 std::to_string(settings.width) + "x" + std::to_string(settings.height) + ")"};
  }
  if (!(settings.fps > 0) || !std::isfinite(settings.fps)) {
    return Error{"VideoSettings: fps must be positive (got " + std::to_string(settings.fps) + ")"};
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->settings = settings;
  const std::string ffmpeg = findProgram(settings.ffmpeg);
  if (ffmpeg.empty()) {
    impl->notice = kMissingNotice;
    return VideoWriter(std::move(impl));
  }
  std::ostringstream command;
  command << shellQuote(ffmpeg) << " -hide_banner -loglevel error -y -f rawvideo -pix_fmt rgba -s "
          << settings.width << "x" << settings.height << " -r " << settings.fps
          << " -i - -pix_fmt yuv420p " << shellQuote(path);
  impl->pipe = popen(command.str().c_str(), "w");
  if (impl->pipe == nullptr) {
    return Error{"VideoWriter: could not start ffmpeg for '" + path + "': " + std::strerror(errno)};
  }
  return VideoWriter(std::move(impl));
}

VideoWriter::VideoWriter(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
VideoWriter::VideoWriter(VideoWriter&&) noexcept = default;
VideoWriter& VideoWriter::operator=(VideoWriter&&) noexcept = default;
VideoWriter::~VideoWriter() = default;

bool VideoWriter::enabled() const { return m_impl->notice.empty(); }
const std::string& VideoWriter::notice() const { return m_impl->notice; }
int VideoWriter::framesWritten() const { return m_impl->frames; }

Status VideoWriter::write(const Image& image) {
  if (!enabled()) return {};
  if (image.width != m_impl->settings.width || image.height != m_impl->settings.height) {
    return Error{"VideoWriter: frame " + std::to_string(m_impl->frames) + " is " + std::to_string(image.width) + "x" +
                 std::to_string(image.height) + " but the video is " + std::to_string(m_impl->settings.width) + "x" +
                 std::to_string(m_impl->settings.height)};
  }
  if (m_impl->pipe == nullptr || m_impl->failed) {
    return Error{"VideoWriter: the pipe to ffmpeg for '" + m_impl->path + "' is closed"};
  }
  std::size_t written = 0;
  {
    ScopedSigpipeBlock block;
    written = std::fwrite(image.rgba.data(), 1, image.rgba.size(), m_impl->pipe);
  }
  if (written != image.rgba.size()) {
    m_impl->failed = true;
    return Error{"VideoWriter: ffmpeg stopped reading while writing '" + m_impl->path + "' (" + std::strerror(errno) +
                 "); call finish() for its exit status"};
  }
  ++m_impl->frames;
  return {};
}

Status VideoWriter::finish() { return m_impl->close(); }

}  // namespace weft
