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

// Reads the status with `status` every 10 ms until `done` holds for it (returned) or `limit`
// has passed (a test failure, with the last status read).
template <typename Read, typename Predicate>
nlohmann::json poll_status(Read status, Predicate done, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  nlohmann::json s;
  while (std::chrono::steady_clock::now() < deadline) {
    s = status();
    if (done(s)) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ADD_FAILURE() << "condition not reached; last status: " << s.dump();
  return s;
}

}  // namespace cncd::test
