// VisitSet, the pending set the projector's late edge sweeps walk (contact/VisitSet.h): the walk
// in both directions against a plain ordered set, word edges, and indices inserted during a walk.
#include "contact/VisitSet.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <vector>

namespace weft {
namespace {

// Every index of `set` from a forward walk, then from a backward walk.
std::vector<Index> walkForward(const VisitSet& set) {
  std::vector<Index> out;
  for (Index i = set.next(0); i != kInvalidIndex; i = set.next(i + 1)) out.push_back(i);
  return out;
}

std::vector<Index> walkBackward(const VisitSet& set, Index count) {
  std::vector<Index> out;
  for (Index i = set.previous(count == 0 ? kInvalidIndex : count - 1); i != kInvalidIndex;
       i = i == 0 ? kInvalidIndex : set.previous(i - 1)) {
    out.push_back(i);
  }
  return out;
}

TEST(VisitSet, AFullSetHoldsExactlyItsIndicesAcrossAPartialLastWord) {
  VisitSet set;
  set.reset(130, true);
  const std::vector<Index> forward = walkForward(set);
  ASSERT_EQ(forward.size(), 130u);
  for (Index i = 0; i < 130; ++i) EXPECT_EQ(forward[i], i);
  EXPECT_EQ(set.next(130), kInvalidIndex);
  EXPECT_EQ(set.previous(1000), 129u);  // past the end: from the last index
  EXPECT_EQ(walkBackward(set, 130).size(), 130u);
}

TEST(VisitSet, AnEmptySetHasNoFirstOrLastIndex) {
  VisitSet set;
  set.reset(0, true);
  EXPECT_EQ(set.next(0), kInvalidIndex);
  EXPECT_EQ(set.previous(kInvalidIndex), kInvalidIndex);
  set.reset(200, false);
  EXPECT_EQ(set.next(0), kInvalidIndex);
  EXPECT_EQ(set.previous(199), kInvalidIndex);
}

TEST(VisitSet, WalksInOrderAsAnOrderedSetDoes) {
  // Random inserts and erases over four words and a bit; every walk matches std::set.
  constexpr Index kCount = 300;
  VisitSet set;
  set.reset(kCount, false);
  std::set<Index> reference;
  std::uint64_t state = 12345;
  for (int step = 0; step < 2000; ++step) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const Index i = Index((state >> 33) % kCount);
    if ((state >> 20) & 1) {
      set.insert(i);
      reference.insert(i);
    } else {
      set.erase(i);
      reference.erase(i);
    }
    ASSERT_EQ(set.contains(i), reference.count(i) == 1);
    if (step % 100 == 0) {
      ASSERT_EQ(walkForward(set), std::vector<Index>(reference.begin(), reference.end()));
      ASSERT_EQ(walkBackward(set, kCount), std::vector<Index>(reference.rbegin(), reference.rend()));
    }
  }
}

TEST(VisitSet, AWalkVisitsWhatIsInsertedAheadOfItAndLeavesWhatIsInsertedBehind) {
  // As a Gauss–Seidel sweep: a correction at index 70 unsettles 3 (behind) and 190 (ahead).
  VisitSet set;
  set.reset(256, false);
  set.insert(70);
  std::vector<Index> visited;
  for (Index i = set.next(0); i != kInvalidIndex; i = set.next(i + 1)) {
    visited.push_back(i);
    set.erase(i);
    if (i == 70) {
      set.insert(3);
      set.insert(190);
    }
  }
  EXPECT_EQ(visited, (std::vector<Index>{70, 190}));
  EXPECT_TRUE(set.contains(3));  // for the next sweep
}

}  // namespace
}  // namespace weft
