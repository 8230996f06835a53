// FrameClock: readings come from std::chrono::steady_clock, never go back, and advance by at
// least a slept interval; the conversions between two readings are exact scalings with a sign.
#include <weft/threading/FrameClock.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <thread>

namespace weft {
namespace {

// The conversions are constant expressions, usable in constexpr budgets.
static_assert(FrameClock::msBetween(0, 1'500'000) == 1.5);
static_assert(FrameClock::usBetween(0, 1'500) == 1.5);

std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

TEST(FrameClock, ConversionsScaleNanosecondsAndKeepTheSign) {
  EXPECT_EQ(FrameClock::msBetween(1'000, 1'000), 0.0);
  EXPECT_DOUBLE_EQ(FrameClock::msBetween(0, 16'666'667), 16.666667);
  EXPECT_EQ(FrameClock::msBetween(2'000'000, 0), -2.0);  // end before begin: negative
  EXPECT_EQ(FrameClock::usBetween(5'000, 3'000), -2.0);
  EXPECT_EQ(FrameClock::usBetween(0, 1), 1e-3);
  // Readings far from zero (the steady clock counts from boot): only the difference matters.
  const std::int64_t late = std::int64_t(1) << 60;
  EXPECT_EQ(FrameClock::msBetween(late, late + 3'000'000), 3.0);
}

TEST(FrameClock, ReadsTheSteadyClock) {
  const std::int64_t before = FrameClock::nowNs();
  const std::int64_t steady = steadyNs();
  const std::int64_t after = FrameClock::nowNs();
  EXPECT_LE(before, steady);
  EXPECT_LE(steady, after);
}

TEST(FrameClock, ReadingsNeverGoBack) {
  std::int64_t previous = FrameClock::nowNs();
  for (int k = 0; k < 100'000; ++k) {
    const std::int64_t now = FrameClock::nowNs();
    ASSERT_GE(now, previous) << "reading " << k;
    previous = now;
  }
}

TEST(FrameClock, AdvancesAtLeastBySleptTime) {
  // sleep_for blocks for at least the duration as measured by the steady clock, so this is a
  // lower bound only; an upper bound would measure the machine's load, not the clock.
  const std::int64_t start = FrameClock::nowNs();
  std::this_thread::sleep_for(std::chrono::milliseconds(3));
  const std::int64_t end = FrameClock::nowNs();
  EXPECT_GE(end - start, 3'000'000);
  EXPECT_GE(FrameClock::msSince(start), 3.0);
  EXPECT_GE(FrameClock::msSince(FrameClock::nowNs()), 0.0);
}

}  // namespace
}  // namespace weft
