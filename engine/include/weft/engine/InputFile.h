// Reading the files a user hands over (OBJ meshes, scene files) without trusting them: only
// regular files, never more than a stated number of bytes, never blocking on a FIFO, and never
// more than the machine's available memory.
#pragma once

#include <weft/Result.h>

#include <cstdint>
#include <string>
#include <string_view>

namespace weft {

/// The whole of a regular file as bytes, or an error naming the file (as "<kind> '<path>'") and
/// the fix: a directory, device, FIFO or socket is refused without being read, and so is a file
/// of more than maxBytes or more than the available memory (a file whose size the file system
/// does not tell, as under /proc, or that grows while read is cut off at maxBytes + 1 and
/// refused). Never blocks on a FIFO, never throws.
Result<std::string> readInputFile(const std::string& path, std::uint64_t maxBytes,
                                  std::string_view kind);

/// Bytes of memory this process can still allocate without swapping: the smaller of the system's
/// MemAvailable (/proc/meminfo; sysconf(_SC_AVPHYS_PAGES) where that is missing) and what is left
/// under the process's cgroup memory.max. Reads the files on every call.
std::uint64_t availableMemoryBytes();

/// Success when `bytes` fit in the available memory (below 64 MiB it is not asked); otherwise an
/// error "<what> needs about X GB of memory, but Y GB are available; <fix>".
Status checkMemory(std::uint64_t bytes, std::string_view what, std::string_view fix);

/// "1.5 GB", "640 MB", "12 kB": a byte count for messages (decimal units, 2 significant digits).
std::string formatBytes(std::uint64_t bytes);

}  // namespace weft
