// The servo loop's wake-up error histogram: the Prometheus buckets it hands the status count
// exactly the samples below each edge, wherever the edge falls among its fine and coarse
// buckets.
#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <random>
#include <vector>

#include "cncd/motion/rt_stats.hpp"
#include "cncd/motion/status.hpp"

namespace cncd::motion {
namespace {

TEST(RtHistogramTest, CountsBelowEachEdgeAsACountOfTheSamplesWould) {
  std::mt19937_64 random(20261129);
  // Mostly small errors, some of milliseconds, a few past the last bucket; and negative ones,
  // which count as on time.
  std::lognormal_distribution<double> late(3.5, 1.8);
  auto histogram = std::make_unique<RtHistogram>();
  std::vector<std::int64_t> samples;
  std::uint64_t sum = 0;
  for (int i = 0; i < 200000; ++i) {
    std::int64_t ns = static_cast<std::int64_t>(late(random) * 1000.0);
    if (i % 97 == 0) ns = -ns;
    if (i % 4999 == 0) ns = 250'000'000;
    histogram->add(ns);
    samples.push_back(ns < 0 ? 0 : ns);
    sum += static_cast<std::uint64_t>(samples.back());
  }
  std::array<std::uint64_t, kWakeEdgesUs.size()> below{};
  histogram->count_below(kWakeEdgesUs.data(), below.data(), kWakeEdgesUs.size());
  for (std::size_t i = 0; i < kWakeEdgesUs.size(); ++i) {
    std::uint64_t expected = 0;
    for (const std::int64_t ns : samples)
      expected += ns < std::int64_t{kWakeEdgesUs[i]} * 1000 ? 1 : 0;
    EXPECT_EQ(below[i], expected) << "below " << kWakeEdgesUs[i] << " us";
    if (i > 0) {
      EXPECT_GE(below[i], below[i - 1]);
    }
  }
  EXPECT_LT(below.back(), histogram->count()) << "the samples past 100 ms are in no bucket";
  EXPECT_EQ(histogram->count(), samples.size());
  EXPECT_EQ(histogram->sum_ns(), sum);
}

TEST(RtHistogramTest, EdgesBetweenTheFineAndCoarseBucketsAndAnEmptyHistogram) {
  RtHistogram histogram;
  const std::int32_t edges[] = {1, 999, 1000, 1100, 99900, 100000};
  std::uint64_t below[6] = {9, 9, 9, 9, 9, 9};
  histogram.count_below(edges, below, 6);
  for (const auto count : below)
    EXPECT_EQ(count, 0u);
  for (const std::int64_t ns : {0LL, 999LL, 1000LL, 998'999LL, 999'000LL, 1'099'999LL, 1'100'000LL,
                                99'899'999LL, 99'900'000LL, 100'000'000LL})
    histogram.add(ns);
  histogram.count_below(edges, below, 6);
  EXPECT_EQ(below[0], 2u);  // 0 and 999 ns
  EXPECT_EQ(below[1], 4u);  // and 1000 ns, 998.999 us
  EXPECT_EQ(below[2], 5u);  // and 999 us
  EXPECT_EQ(below[3], 6u);  // and 1099.999 us
  EXPECT_EQ(below[4], 8u);  // and 1100 us, 99899.999 us
  EXPECT_EQ(below[5], 9u);  // and 99900 us; not 100 ms
}

}  // namespace
}  // namespace cncd::motion
