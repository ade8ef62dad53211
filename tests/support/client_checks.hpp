// Checks made through a client on a daemon the tests run.
#pragma once

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "client.hpp"

namespace cncd::test {

// The machine, seen in `status` after a stop, stands short of X 200 (where the long test moves
// end) and commands nothing further: X is still there `wait` later.
inline void expect_stopped_short_of_x200(daemon::Client& client, const nlohmann::json& status,
                                         std::chrono::milliseconds wait) {
  const double x = status["position"]["commanded"]["x"];
  std::this_thread::sleep_for(wait);
  const nlohmann::json answer = client.call("status.get");
  EXPECT_TRUE(answer.contains("result")) << answer.dump();
  const nlohmann::json later = answer.value("result", nlohmann::json());
  EXPECT_EQ(later["position"]["commanded"]["x"].get<double>(), x);
  EXPECT_LT(x, 200.0);
}

}  // namespace cncd::test
