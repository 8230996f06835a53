#include <weft/engine/InputFile.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

namespace weft {
namespace {

// Allocations below this are not checked against the available memory: reading /proc costs
// tens of microseconds, and a failure that small would fail everything else too.
constexpr std::uint64_t kUncheckedBytes = 64ull << 20;

const char* fileKind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Closes a file descriptor on every path out of readInputFile.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

// The value of `key` (in kB) in /proc/meminfo, or 0 when absent.
std::uint64_t meminfoBytes(const char* key) {
  std::ifstream file("/proc/meminfo");
  std::string name;
  std::uint64_t kilobytes = 0;
  std::string unit;
  while (file >> name >> kilobytes) {
    std::getline(file, unit);
    if (name == key) return kilobytes * 1024;
  }
  return 0;
}

// What the cgroup (v2) of this process may still use, or the largest value when unlimited or
// unknown.
std::uint64_t cgroupHeadroomBytes() {
  constexpr std::uint64_t kUnlimited = std::numeric_limits<std::uint64_t>::max();
  std::ifstream self("/proc/self/cgroup");
  std::string line, group;
  while (std::getline(self, line)) {
    if (line.rfind("0::", 0) == 0) group = line.substr(3);
  }
  if (group.empty()) return kUnlimited;
  const std::string directory = "/sys/fs/cgroup" + (group == "/" ? std::string() : group);
  std::ifstream maxFile(directory + "/memory.max"), currentFile(directory + "/memory.current");
  std::string limit;
  std::uint64_t current = 0;
  if (!(maxFile >> limit) || limit == "max" || !(currentFile >> current)) return kUnlimited;
  const std::uint64_t maximum = std::strtoull(limit.c_str(), nullptr, 10);
  return maximum > current ? maximum - current : 0;
}

}  // namespace

std::string formatBytes(std::uint64_t bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  double value = double(bytes);
  int unit = 0;
  while (value >= 1000 && unit < 6) {
    value /= 1000;
    ++unit;
  }
  char text[32];
  if (unit == 0) std::snprintf(text, sizeof(text), "%llu bytes", static_cast<unsigned long long>(bytes));
  else std::snprintf(text, sizeof(text), value < 10 ? "%.1f %s" : "%.0f %s", value, units[unit]);
  return text;
}

std::uint64_t availableMemoryBytes() {
  std::uint64_t available = meminfoBytes("MemAvailable:");
  if (available == 0) {
    const long pages = ::sysconf(_SC_AVPHYS_PAGES), pageSize = ::sysconf(_SC_PAGESIZE);
    if (pages > 0 && pageSize > 0) available = std::uint64_t(pages) * std::uint64_t(pageSize);
  }
  return std::min(available, cgroupHeadroomBytes());
}

Status checkMemory(std::uint64_t bytes, std::string_view what, std::string_view fix) {
  if (bytes < kUncheckedBytes) return Status::success();
  const std::uint64_t available = availableMemoryBytes();
  if (bytes <= available) return Status::success();
  return Error{std::string(what) + " needs about " + formatBytes(bytes) + " of memory, but " +
               formatBytes(available) + " are available; " + std::string(fix)};
}

Result<std::string> readInputFile(const std::string& path, std::uint64_t maxBytes,
                                  std::string_view kind) {
  const std::string name = std::string(kind) + " '" + path + "'";
  // O_NONBLOCK: opening a FIFO without a writer would otherwise wait forever. The type is then
  // checked on the open descriptor, so the file cannot be swapped between check and read.
  Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (file.fd < 0) {
    const int error = errno;
    return Error{"cannot read " + name + ": " + std::strerror(error) +
                 "; check the path and the permissions"};
  }
  struct stat status {};
  if (::fstat(file.fd, &status) != 0) {
    return Error{"cannot read " + name + ": " + std::strerror(errno) + "; check the path"};
  }
  if (!S_ISREG(status.st_mode)) {
    return Error{"cannot read " + name + ": it is " + fileKind(status.st_mode) +
                 ", not a regular file; give the path of a file"};
  }
  const std::string limit = "the limit of " + std::to_string(maxBytes) + " bytes" +
                            (maxBytes >= 1000 ? " (" + formatBytes(maxBytes) + ")" : std::string()) +
                            " for " + std::string(kind) + "s";
  if (std::uint64_t(status.st_size) > maxBytes) {
    return Error{name + " is " + std::to_string(status.st_size) + " bytes, more than " + limit +
                 "; give a smaller file"};
  }
  // Reading is blocking again (a regular file never waits, but some file systems honour the flag).
  const int flags = ::fcntl(file.fd, F_GETFL);
  if (flags >= 0) (void)::fcntl(file.fd, F_SETFL, flags & ~O_NONBLOCK);
  std::string text;
  // st_size is a hint only (files under /proc report 0, a file may grow): read until the end or
  // one byte past the limit.
  if (Status memory = checkMemory(std::uint64_t(status.st_size), "reading " + name, "give a smaller file");
      !memory.ok()) {
    return memory.error();
  }
  text.reserve(std::size_t(status.st_size));
  char buffer[1 << 16];
  for (;;) {
    const std::uint64_t room = maxBytes + 1 - text.size();
    const ssize_t got = ::read(file.fd, buffer, std::size_t(std::min<std::uint64_t>(sizeof(buffer), room)));
    if (got < 0) {
      if (errno == EINTR) continue;
      return Error{"cannot read " + name + ": " + std::strerror(errno) + "; check the file"};
    }
    if (got == 0) break;
    text.append(buffer, std::size_t(got));
    if (text.size() > maxBytes) {
      return Error{name + " is larger than " + limit +
                   " (found while reading it: its size was not known, or it grew); give a smaller file"};
    }
  }
  return text;
}

}  // namespace weft
