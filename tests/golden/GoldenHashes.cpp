#include "golden/GoldenHashes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#if !defined(WEFT_GOLDEN_FILE) || !defined(WEFT_GOLDEN_REFERENCE_BUILD)
#error "tests/CMakeLists.txt defines WEFT_GOLDEN_FILE and WEFT_GOLDEN_REFERENCE_BUILD (0 or 1)"
#endif

namespace weft::test {
namespace {

constexpr bool kReferenceBuild = WEFT_GOLDEN_REFERENCE_BUILD;

bool environmentIsOne(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr && std::string(value) == "1";
}

// Parses golden-file text; `origin` names it in errors.
GoldenFile parseGoldenText(const std::string& text, const std::string& origin) {
  GoldenFile file;
  if (text.empty()) return file;
  const nlohmann::json document = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded() || !document.is_object()) {
    file.error = origin + " is not a JSON object of \"key\": \"0x…\" pairs; restore it from git";
    return file;
  }
  for (const auto& [key, value] : document.items()) {
    const std::optional<std::uint64_t> hash =
        value.is_string() ? parseHash(value.get<std::string>()) : std::nullopt;
    if (!hash) {
      file.error = origin + ": the value of \"" + key + "\" is not a hash \"0x\" + 16 hex digits";
      return file;
    }
    file.hashes[key] = *hash;
  }
  return file;
}

std::string goldenText(const std::map<std::string, std::uint64_t>& hashes) {
  nlohmann::json document = nlohmann::json::object();
  for (const auto& [key, hash] : hashes) document[key] = formatHash(hash);
  return document.dump(2) + "\n";
}

// Reads all of an open file from its start.
std::string readAll(int fd) {
  std::string text;
  char buffer[4096];
  off_t offset = 0;
  for (;;) {
    const ssize_t got = pread(fd, buffer, sizeof buffer, offset);
    if (got <= 0) break;
    text.append(buffer, std::size_t(got));
    offset += got;
  }
  return text;
}

// Sets `key` in the golden file under an exclusive lock (parallel CTest processes write it at
// once); returns an error message, empty on success. `previous` gets the old value, if any.
std::string updateKey(const std::string& path, const std::string& key, std::uint64_t hash,
                      std::optional<std::uint64_t>& previous) {
  const int fd = open(path.c_str(), O_RDWR | O_CREAT, 0644);
  if (fd < 0) return "cannot open " + path + " for writing; check that the source tree is writable";
  std::string error;
  if (flock(fd, LOCK_EX) != 0) {
    error = "cannot lock " + path;
  } else {
    GoldenFile file = parseGoldenText(readAll(fd), path);
    if (!file.error.empty()) {
      error = file.error;
    } else {
      if (auto found = file.hashes.find(key); found != file.hashes.end()) previous = found->second;
      if (previous != hash) {
        file.hashes[key] = hash;
        const std::string text = goldenText(file.hashes);
        if (ftruncate(fd, 0) != 0 || pwrite(fd, text.data(), text.size(), 0) != ssize_t(text.size())) {
          error = "cannot write " + path;
        }
      }
    }
  }
  close(fd);  // releases the lock
  return error;
}

// Appends "key hash" to $WEFT_GOLDEN_SEEN in one write (O_APPEND keeps parallel lines whole).
void recordSeen(const std::string& key, std::uint64_t hash) {
  const char* seen = std::getenv("WEFT_GOLDEN_SEEN");
  if (seen == nullptr || *seen == '\0') return;
  const int fd = open(seen, O_WRONLY | O_APPEND | O_CREAT, 0644);
  if (fd < 0) {
    ADD_FAILURE() << "cannot append to WEFT_GOLDEN_SEEN=" << seen;
    return;
  }
  const std::string line = key + " " + formatHash(hash) + "\n";
  if (write(fd, line.data(), line.size()) != ssize_t(line.size())) {
    ADD_FAILURE() << "cannot append to WEFT_GOLDEN_SEEN=" << seen;
  }
  close(fd);
}

}  // namespace

std::string formatHash(std::uint64_t hash) {
  char text[19];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(hash));
  return text;
}

std::optional<std::uint64_t> parseHash(const std::string& text) {
  if (text.size() != 18 || text[0] != '0' || text[1] != 'x') return std::nullopt;
  std::uint64_t hash = 0;
  for (std::size_t k = 2; k < text.size(); ++k) {
    const char c = text[k];
    int digit = -1;
    if (c >= '0' && c <= '9') digit = c - '0';
    if (c >= 'a' && c <= 'f') digit = c - 'a' + 10;
    if (c >= 'A' && c <= 'F') digit = c - 'A' + 10;
    if (digit < 0) return std::nullopt;
    hash = hash << 4 | std::uint64_t(digit);
  }
  return hash;
}

std::string goldenFilePath() { return WEFT_GOLDEN_FILE; }

GoldenFile readGoldenFile(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) return {};
  std::ostringstream text;
  text << stream.rdbuf();
  return parseGoldenText(text.str(), path);
}

std::string writeGoldenFile(const std::string& path, const std::map<std::string, std::uint64_t>& hashes) {
  const std::string text = goldenText(hashes);
  {
    std::ifstream existing(path, std::ios::binary);
    std::ostringstream old;
    if (existing) old << existing.rdbuf();
    if (existing && old.str() == text) return {};
  }
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream << text;
  return stream ? std::string() : "cannot write " + path;
}

void expectGoldenHash(const std::string& key, std::uint64_t measured) {
  // The same key twice in one process must carry one hash: two scenes may not share a name.
  static std::mutex mutex;
  static std::map<std::string, std::uint64_t> checked;
  {
    std::lock_guard lock(mutex);
    auto [slot, inserted] = checked.emplace(key, measured);
    if (!inserted && slot->second != measured) {
      ADD_FAILURE() << "golden key '" << key << "' was checked twice with different hashes ("
                    << formatHash(slot->second) << " and " << formatHash(measured)
                    << "): give each scene its own name";
    }
  }
  ::testing::Test::RecordProperty("golden:" + key, formatHash(measured));
  recordSeen(key, measured);
  const std::string path = goldenFilePath();
  const bool update = environmentIsOne("WEFT_UPDATE_GOLDEN");
  if (!kReferenceBuild) {
    if (update) {
      ADD_FAILURE() << "WEFT_UPDATE_GOLDEN=1 in a build that is not the reference build (Release, "
                       "GCC, x86-64, no sanitizer): its hashes would not be the reference's";
    } else {
      std::printf("[golden   ] %s = %s (not compared: the golden hashes are those of the Release "
                  "build with GCC on x86-64 without sanitizers)\n", key.c_str(), formatHash(measured).c_str());
    }
    return;
  }
  if (update) {
    std::optional<std::uint64_t> previous;
    const std::string error = updateKey(path, key, measured, previous);
    if (!error.empty()) {
      ADD_FAILURE() << "golden key '" << key << "': " << error;
    } else if (previous == measured) {
      std::printf("[golden   ] %s = %s (unchanged)\n", key.c_str(), formatHash(measured).c_str());
    } else {
      std::printf("[golden   ] %s = %s (UPDATED, was %s)\n", key.c_str(), formatHash(measured).c_str(),
                  previous ? formatHash(*previous).c_str() : "missing");
    }
    return;
  }
  const GoldenFile file = readGoldenFile(path);
  if (!file.error.empty()) {
    ADD_FAILURE() << "golden key '" << key << "': " << file.error;
    return;
  }
  const auto found = file.hashes.find(key);
  if (found == file.hashes.end()) {
    ADD_FAILURE() << "golden hash '" << key << "' is missing from " << path << " (measured "
                  << formatHash(measured) << "). Add it with " << kGoldenUpdateCommand
                  << " and commit the file.";
    return;
  }
  if (found->second != measured) {
    ADD_FAILURE() << "golden hash '" << key << "' differs: expected " << formatHash(found->second)
                  << ", measured " << formatHash(measured) << " (" << path
                  << "). A change that moves no bit must keep it; if the bits are meant to move, "
                  << "run " << kGoldenUpdateCommand << " and commit the file saying why they moved.";
    return;
  }
  std::printf("[golden   ] %s = %s (matches)\n", key.c_str(), formatHash(measured).c_str());
}

int pruneGoldenFile(const std::string& goldenPath, const std::string& seenPath, bool dropUnseen) {
  std::ifstream seen(seenPath);
  if (!seen) {
    std::printf("update-golden-hashes: no check wrote to %s: did the golden tests run?\n", seenPath.c_str());
    return 1;
  }
  std::map<std::string, std::set<std::uint64_t>> measured;
  std::string line;
  while (std::getline(seen, line)) {
    const std::size_t space = line.rfind(' ');
    const std::optional<std::uint64_t> hash =
        space == std::string::npos ? std::nullopt : parseHash(line.substr(space + 1));
    if (!hash) {
      std::printf("update-golden-hashes: %s: malformed line '%s'\n", seenPath.c_str(), line.c_str());
      return 1;
    }
    measured[line.substr(0, space)].insert(*hash);
  }
  int status = 0;
  for (const auto& [key, hashes] : measured) {
    if (hashes.size() > 1) {
      std::printf("update-golden-hashes: key '%s' was written with %zu different hashes (two "
                  "scenes share a name, or a run is not deterministic)\n", key.c_str(), hashes.size());
      status = 1;
    }
  }
  GoldenFile file = readGoldenFile(goldenPath);
  if (!file.error.empty()) {
    std::printf("update-golden-hashes: %s\n", file.error.c_str());
    return 1;
  }
  std::vector<std::string> unseen;
  for (const auto& [key, hash] : file.hashes) {
    if (!measured.count(key)) unseen.push_back(key);
  }
  for (const std::string& key : unseen) {
    std::printf("update-golden-hashes: no check wrote '%s': %s\n", key.c_str(),
                dropUnseen ? "removed" : "kept (some golden test failed; removal needs a clean run)");
    if (dropUnseen) file.hashes.erase(key);
  }
  if (const std::string error = writeGoldenFile(goldenPath, file.hashes); !error.empty()) {
    std::printf("update-golden-hashes: %s\n", error.c_str());
    return 1;
  }
  std::printf("update-golden-hashes: %zu keys measured, %zu in %s\n", measured.size(),
              file.hashes.size(), goldenPath.c_str());
  return status;
}

}  // namespace weft::test
