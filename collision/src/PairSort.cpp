// LSD radix sort of triangle pairs. See PairSort.h.
#include "PairSort.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>

namespace weft::detail {

void sortTrianglePairs(std::vector<TrianglePair>& pairs, Index indexBound) {
  const std::size_t count = pairs.size();
  // Below ~1,000 elements the comparison sort is as fast and needs no scratch.
  if (count < 1024) {
    std::sort(pairs.begin(), pairs.end());
    return;
  }
  const int indexBits = std::max(1, int(std::bit_width(std::max<Index>(indexBound, 2) - 1)));
  auto key = [indexBits](const TrianglePair& pair) {
    return (std::uint64_t(pair.first) << indexBits) | pair.second;
  };
  // As few passes as digits of at most 12 bits allow (3 passes up to 2^18 triangles), the
  // digits as even as possible.
  constexpr int kMaxDigitBits = 12;
  constexpr std::size_t kRadix = std::size_t(1) << kMaxDigitBits;
  const int keyBits = 2 * indexBits;
  const int passes = (keyBits + kMaxDigitBits - 1) / kMaxDigitBits;
  const int digitBits = (keyBits + passes - 1) / passes;
  const std::uint64_t digitMask = (std::uint64_t(1) << digitBits) - 1;

  pairs.resize(2 * count);
  TrianglePair* source = pairs.data();
  TrianglePair* target = source + count;
  std::array<std::size_t, kRadix> offsets;
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = pass * digitBits;
    offsets.fill(0);
    for (std::size_t i = 0; i < count; ++i) ++offsets[(key(source[i]) >> shift) & digitMask];
    // All keys share this digit: the pass would be the identity.
    if (*std::max_element(offsets.begin(), offsets.end()) == count) continue;
    std::size_t running = 0;
    for (std::size_t& offset : offsets) {
      const std::size_t bucket = offset;
      offset = running;
      running += bucket;
    }
    for (std::size_t i = 0; i < count; ++i) {
      target[offsets[(key(source[i]) >> shift) & digitMask]++] = source[i];
    }
    std::swap(source, target);
  }
  if (source != pairs.data()) std::copy(source, source + count, pairs.data());
  pairs.resize(count);
}

}  // namespace weft::detail
