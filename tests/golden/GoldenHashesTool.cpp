// weft-golden-hashes: the last step of tools/update-golden-hashes.
//
//   weft-golden-hashes prune SEEN_FILE [--keep-unseen]
//
// SEEN_FILE holds the "key hash" lines the golden checks appended in update mode
// (WEFT_GOLDEN_SEEN). A key written with two different hashes is an error; keys of the golden
// file that no check wrote are removed, or kept with --keep-unseen (after a run in which some
// golden test failed, so its key may simply not have been reached).
#include "golden/GoldenHashes.h"

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  const bool keepUnseen = argc == 4 && std::string(argv[3]) == "--keep-unseen";
  if (argc < 3 || std::string(argv[1]) != "prune" || (argc == 4 && !keepUnseen) || argc > 4) {
    std::fprintf(stderr, "usage: %s prune SEEN_FILE [--keep-unseen]\n", argv[0]);
    return 2;
  }
  return weft::test::pruneGoldenFile(weft::test::goldenFilePath(), argv[2], !keepUnseen);
}
