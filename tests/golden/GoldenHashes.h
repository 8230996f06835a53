// Golden state hashes: the final World::stateHash() of the reference scenes (the curtain, every
// stress scene, every shipped scene file, the rod scene), pinned in tests/golden/state-hashes.json,
// so that a change that moves one bit of a simulation fails a test instead of passing unseen.
//
// Compare mode (the default): a key missing from the file, or a hash that differs from its value,
// is a test failure that names the key, the expected and the measured hash and the update command.
// Update mode (WEFT_UPDATE_GOLDEN=1, set by tools/update-golden-hashes): the measured hash is
// written into the file instead. CTest runs the checks as parallel processes, so each write takes
// an exclusive lock (flock) on the file, reads it, sets the one key and rewrites it only when the
// value changed; keys are sorted (one "key": "0x…" line each), so a run that moves no bit leaves
// the file byte-identical. WEFT_GOLDEN_SEEN=<file> additionally appends "key hash" lines, from
// which the update command drops keys that no check wrote any more (pruneGoldenFile).
//
// The hashes hold for the reference build: Release, GCC, x86-64, no sanitizer
// (WEFT_GOLDEN_REFERENCE_BUILD, set by tests/CMakeLists.txt). Other compilers and flags may
// round differently, so in any other build a check prints why it compares nothing.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

namespace weft::test {

/// The command that rewrites the golden file, for failure messages and documentation.
inline constexpr const char* kGoldenUpdateCommand = "tools/update-golden-hashes";

/// "0x" and 16 lower-case hex digits, the form the golden file stores.
std::string formatHash(std::uint64_t hash);
/// The inverse of formatHash (also accepts upper-case digits); none for anything else.
std::optional<std::uint64_t> parseHash(const std::string& text);

/// Path of the checked-in golden file (tests/golden/state-hashes.json of the source tree).
std::string goldenFilePath();

/// Checks `measured` against the golden file's value under `key` as a GoogleTest expectation
/// (compare mode), or writes it there (update mode); see the note at the top. Keys are
/// "<group>/<name>", e.g. "stress/twisted_strip"; the same key checked twice in one process
/// with different hashes is a failure (two scenes sharing a name).
void expectGoldenHash(const std::string& key, std::uint64_t measured);

/// Reads a golden file: key → hash. An error message names the file and what is wrong.
struct GoldenFile {
  std::map<std::string, std::uint64_t> hashes;
  std::string error;  ///< empty when read (a missing file reads as empty)
};
GoldenFile readGoldenFile(const std::string& path);

/// Writes `hashes` (sorted, one per line) to `path` when the text differs from the file's;
/// returns an error message, empty on success.
std::string writeGoldenFile(const std::string& path, const std::map<std::string, std::uint64_t>& hashes);

/// The update command's last step: reads the "key hash" lines a run appended to `seenPath`,
/// fails on a key seen with two different hashes, and, when `dropUnseen`, removes from the golden
/// file every key no check wrote. Prints what it did to stdout; returns the process exit code.
int pruneGoldenFile(const std::string& goldenPath, const std::string& seenPath, bool dropUnseen);

}  // namespace weft::test
