// VisitSet: the indices a Gauss–Seidel sweep still has to visit, as a bitset the sweep walks in
// order (forward or backward) while its own corrections add indices ahead of it.
//
// A sweep over thousands of constraints of which a few are still active (the late sweeps of a
// strain limit converging near a contact) spends its time finding them; walking the set bits
// costs a word per 64 indices instead. The walk re-reads each word as it goes, so an index
// inserted ahead of the walk is visited in the same sweep, one behind it in the next, exactly as
// a full sweep that skips settled indices would visit them.
#pragma once

#include <weft/Math.h>

#include <bit>
#include <cstdint>
#include <vector>

namespace weft {

class VisitSet {
 public:
  /// `count` indices, all in the set (`all`) or none. Allocates only when count grows.
  void reset(Index count, bool all) {
    m_count = count;
    m_words.assign((std::size_t(count) + 63) / 64, all ? ~std::uint64_t(0) : 0);
    if (all && count % 64 != 0) m_words.back() = (std::uint64_t(1) << (count % 64)) - 1;
  }

  void insert(Index i) { m_words[i >> 6] |= bit(i); }
  void erase(Index i) { m_words[i >> 6] &= ~bit(i); }
  bool contains(Index i) const { return (m_words[i >> 6] & bit(i)) != 0; }

  /// The least index ≥ `from` in the set; kInvalidIndex when there is none.
  Index next(Index from) const {
    if (from >= m_count) return kInvalidIndex;
    std::size_t word = from >> 6;
    std::uint64_t bits = m_words[word] & (~std::uint64_t(0) << (from & 63));
    while (bits == 0) {
      if (++word == m_words.size()) return kInvalidIndex;
      bits = m_words[word];
    }
    return Index(word * 64 + std::countr_zero(bits));
  }

  /// The greatest index ≤ `from` in the set (from = kInvalidIndex: none); kInvalidIndex when
  /// there is none.
  Index previous(Index from) const {
    if (from == kInvalidIndex || m_count == 0) return kInvalidIndex;
    if (from >= m_count) from = m_count - 1;
    std::size_t word = from >> 6;
    std::uint64_t bits = m_words[word] & (~std::uint64_t(0) >> (63 - (from & 63)));
    while (bits == 0) {
      if (word-- == 0) return kInvalidIndex;
      bits = m_words[word];
    }
    return Index(word * 64 + 63 - std::countl_zero(bits));
  }

 private:
  static std::uint64_t bit(Index i) { return std::uint64_t(1) << (i & 63); }

  std::vector<std::uint64_t> m_words;
  Index m_count = 0;
};

}  // namespace weft
