// WatchdogGate: systemd's watchdog is fed while the servo heartbeat advances, and only then.
#include "watchdog_gate.hpp"

#include <gtest/gtest.h>

namespace cncd::daemon {
namespace {

using std::chrono::milliseconds;
using Clock = WatchdogGate::Clock;

TEST(WatchdogGate, FeedsWhileTheHeartbeatAdvances) {
  const Clock::time_point t0{};
  WatchdogGate gate(milliseconds(500), t0, 100);
  EXPECT_FALSE(gate.feed(t0 + milliseconds(10), 110));  // interval not yet passed
  EXPECT_FALSE(gate.feed(t0 + milliseconds(499), 600));
  EXPECT_TRUE(gate.feed(t0 + milliseconds(500), 600));
  EXPECT_FALSE(gate.feed(t0 + milliseconds(700), 800));  // 200 ms after the last check
  EXPECT_TRUE(gate.feed(t0 + milliseconds(1000), 1100));
  EXPECT_TRUE(gate.feed(t0 + milliseconds(1600), 1101));  // any advance counts
}

TEST(WatchdogGate, StopsWhenTheHeartbeatStopsAndResumes) {
  const Clock::time_point t0{};
  WatchdogGate gate(milliseconds(500), t0, 7);
  EXPECT_TRUE(gate.feed(t0 + milliseconds(500), 500));
  // The servo thread hangs: its heartbeat stays at 500, however long the main loop runs.
  for (int i = 2; i <= 10; ++i)
    EXPECT_FALSE(gate.feed(t0 + milliseconds(500 * i), 500)) << "check " << i;
  // It runs again: the first check that sees it move feeds again.
  EXPECT_FALSE(gate.feed(t0 + milliseconds(5200), 900));  // within the interval
  EXPECT_TRUE(gate.feed(t0 + milliseconds(5500), 900));
  EXPECT_TRUE(gate.feed(t0 + milliseconds(6000), 1400));
}

}  // namespace
}  // namespace cncd::daemon
