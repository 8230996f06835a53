// Replays fuzz inputs through a libFuzzer target's entry point without libFuzzer, so that the
// corpora (tests/fuzz/corpus/<target>/) run as ordinary CTest cases in the normal (GCC) build:
// what the fuzzers once found stays fixed without clang.
//
//   <target>-replay FILE...
//
// Each file is read whole into a buffer of exactly its size (as libFuzzer passes it, so a read
// past the end is a real overrun under AddressSanitizer) and handed to LLVMFuzzerTestOneInput.
// A crash or trap fails the test; a file that cannot be read is an error naming it.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE...: feeds each file to the fuzz target\n", argv[0]);
    return 2;
  }
  for (int k = 1; k < argc; ++k) {
    std::ifstream stream(argv[k], std::ios::binary);
    if (!stream) {
      std::fprintf(stderr, "%s: cannot read '%s'; check the path\n", argv[0], argv[k]);
      return 1;
    }
    const std::vector<char> bytes{std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
    const std::unique_ptr<std::uint8_t[]> data(new std::uint8_t[bytes.size() + (bytes.empty() ? 1 : 0)]);
    std::copy(bytes.begin(), bytes.end(), data.get());
    const int result = LLVMFuzzerTestOneInput(data.get(), bytes.size());
    std::printf("replayed %s (%zu bytes): returned %d\n", argv[k], bytes.size(), result);
    if (result != 0) {
      std::fprintf(stderr, "%s: the target returned %d (libFuzzer accepts only 0)\n", argv[k], result);
      return 1;
    }
  }
  return 0;
}
