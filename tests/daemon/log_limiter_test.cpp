// A message repeated every turn reaches the log a few times a period, and the next one logged
// says how many were left out.
#include <gtest/gtest.h>

#include "logging.hpp"

namespace cncd::daemon {
namespace {

TEST(LogLimiter, LetsABurstThroughPerPeriodAndCountsTheRest) {
  LogLimiter limiter(std::chrono::minutes(1), 3);
  const auto t0 = LogLimiter::Clock::time_point() + std::chrono::hours(1);
  int logged = 0;
  for (int i = 0; i < 1000; ++i)
    logged += limiter.log(spdlog::level::debug, "accept failed", t0 + std::chrono::milliseconds(i))
                  ? 1
                  : 0;
  EXPECT_EQ(logged, 3);
  EXPECT_EQ(limiter.left_out(), 997u);
  EXPECT_TRUE(limiter.log(spdlog::level::debug, "accept failed", t0 + std::chrono::minutes(1)));
  EXPECT_EQ(limiter.left_out(), 0u);
}

}  // namespace
}  // namespace cncd::daemon
