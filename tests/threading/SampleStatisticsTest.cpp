// SampleStatistics: the nearest-rank percentile and the mean behind every report's p50/p95/p99,
// on inputs whose answers are worked out by hand (SampleStatistics.h states the contract).
#include <weft/threading/SampleStatistics.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace weft {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// 1, 2, …, n in a scrambled order (the percentile sorts a copy).
std::vector<double> oneTo(int n) {
  std::vector<double> samples;
  for (int k = 0; k < n; ++k) samples.push_back(double((k * 7) % n + 1));  // 7 is prime to n below
  return samples;
}

TEST(SampleStatistics, NoSamplesGiveZero) {
  for (double p : {0.0, 50.0, 99.0, 100.0}) EXPECT_EQ(percentile({}, p), 0.0) << p;
  EXPECT_EQ(mean({}), 0.0);
}

TEST(SampleStatistics, OneSampleIsEveryPercentile) {
  for (double p : {0.0, 1.0, 50.0, 95.0, 99.0, 100.0}) EXPECT_EQ(percentile({4.25}, p), 4.25) << p;
  EXPECT_EQ(mean({4.25}), 4.25);
}

TEST(SampleStatistics, OddCountTakesTheMiddleSampleAtP50) {
  const std::vector<double> samples{5, 1, 3};  // sorted 1 3 5
  EXPECT_EQ(percentile(samples, 0), 1);        // rank 1 by definition
  EXPECT_EQ(percentile(samples, 33), 1);       // ⌈0.99⌉ = 1
  EXPECT_EQ(percentile(samples, 34), 3);       // ⌈1.02⌉ = 2
  EXPECT_EQ(percentile(samples, 50), 3);       // ⌈1.5⌉ = 2
  EXPECT_EQ(percentile(samples, 67), 5);       // ⌈2.01⌉ = 3
  EXPECT_EQ(percentile(samples, 100), 5);
  EXPECT_EQ(mean(samples), 3);
}

TEST(SampleStatistics, EvenCountTakesTheLowerMiddleSampleAtP50NotAnAverage) {
  const std::vector<double> samples{4, 1, 3, 2};  // sorted 1 2 3 4
  EXPECT_EQ(percentile(samples, 25), 1);          // ⌈1⌉ = 1
  EXPECT_EQ(percentile(samples, 26), 2);          // ⌈1.04⌉ = 2
  EXPECT_EQ(percentile(samples, 50), 2);          // ⌈2⌉ = 2: a sample, not 2.5
  EXPECT_EQ(percentile(samples, 51), 3);          // ⌈2.04⌉ = 3
  EXPECT_EQ(percentile(samples, 75), 3);
  EXPECT_EQ(percentile(samples, 76), 4);
  EXPECT_EQ(mean(samples), 2.5);
}

TEST(SampleStatistics, ReportPercentilesOfAHundredAndOfTwentySamples) {
  const std::vector<double> hundred = oneTo(100);
  EXPECT_EQ(percentile(hundred, 50), 50);
  EXPECT_EQ(percentile(hundred, 95), 95);
  EXPECT_EQ(percentile(hundred, 99), 99);
  EXPECT_EQ(percentile(hundred, 100), 100);
  // 7 / 100 · 100 is 7.000000000000001 in doubles: a rank computed that way would be 8.
  EXPECT_EQ(percentile(hundred, 7), 7);
  EXPECT_EQ(percentile(hundred, 99.5), 100);  // ⌈99.5⌉
  EXPECT_EQ(mean(hundred), 50.5);

  const std::vector<double> twenty = oneTo(20);
  EXPECT_EQ(percentile(twenty, 50), 10);  // ⌈10⌉
  EXPECT_EQ(percentile(twenty, 95), 19);  // ⌈19⌉
  EXPECT_EQ(percentile(twenty, 99), 20);  // ⌈19.8⌉
}

TEST(SampleStatistics, TiesAreOrdinarySamples) {
  const std::vector<double> samples{2, 5, 2, 2};  // sorted 2 2 2 5
  EXPECT_EQ(percentile(samples, 50), 2);
  EXPECT_EQ(percentile(samples, 75), 2);  // ⌈3⌉ = 3
  EXPECT_EQ(percentile(samples, 76), 5);  // ⌈3.04⌉ = 4
  EXPECT_EQ(percentile({3, 3, 3}, 99), 3);
  EXPECT_EQ(mean(samples), 2.75);
}

TEST(SampleStatistics, PercentOutsideZeroToHundredIsClamped) {
  const std::vector<double> samples{4, 1, 3, 2};
  EXPECT_EQ(percentile(samples, -10), 1);
  EXPECT_EQ(percentile(samples, 150), 4);
  EXPECT_EQ(percentile(samples, -kInfinity), 1);
  EXPECT_EQ(percentile(samples, kInfinity), 4);
}

TEST(SampleStatistics, NaNPoisonsTheResultInsteadOfLandingAtARandomRank) {
  EXPECT_TRUE(std::isnan(percentile({1, kNaN, 3}, 50)));
  EXPECT_TRUE(std::isnan(percentile({kNaN}, 0)));
  EXPECT_TRUE(std::isnan(percentile({1, 2, 3}, kNaN)));
  EXPECT_TRUE(std::isnan(mean({1, kNaN, 3})));
}

TEST(SampleStatistics, InfinitiesSortLikeNumbers) {
  const std::vector<double> samples{kInfinity, 1, -kInfinity, 2};  // sorted −∞ 1 2 +∞
  EXPECT_EQ(percentile(samples, 0), -kInfinity);
  EXPECT_EQ(percentile(samples, 50), 1);
  EXPECT_EQ(percentile(samples, 75), 2);
  EXPECT_EQ(percentile(samples, 100), kInfinity);
}

TEST(SampleStatistics, TheCallersSamplesAreLeftInTheirOrder) {
  const std::vector<double> samples{3, 1, 2};
  (void)percentile(samples, 50);
  EXPECT_EQ(samples, (std::vector<double>{3, 1, 2}));
}

}  // namespace
}  // namespace weft
