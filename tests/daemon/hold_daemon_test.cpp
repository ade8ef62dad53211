// A feed hold or an abort during a rapid's acceleration on the real daemon (the simulated mill,
// G0 X123.4 Y56.7 Z-8.9: 220 mm/s reached after 100 ms): the hold comes to rest and resume
// ends at the target; the abort is answered and leaves the machine idle, taking MDI; with
// [SPINDLE_0] STOP_ON_PAUSE the hold stops the spindle and resume turns it again.
#include <fstream>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;
using std::chrono::milliseconds;

constexpr double kX = 123.4;
constexpr double kY = 56.7;
constexpr double kZ = -8.9;
// After the rapid's start: within its acceleration (100 ms).
constexpr int kDelaysMs[] = {20, 55, 90};

class HoldDaemon : public MachineTest {
 protected:
  // Restarts cncd with `keys` added to [SPINDLE_0].
  void restart_with_spindle_keys(const std::string& keys) {
    daemon_.stop();
    std::string text = slurp(ini_);
    const std::string section = "[SPINDLE_0]\n";
    text.insert(text.find(section) + section.size(), keys);
    std::ofstream(ini_, std::ios::trunc) << text;
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }

  // Back to machine zero, then `before` and the rapid in a program, held (`stop`) `delay_ms`
  // after the rapid has started to move.
  void rapid_then(const std::string& stop, int delay_ms, const std::string& before = "") {
    start_program("zero.ngc", "G21 G90 G0 X0 Y0 Z0\nM2\n");
    wait_until([](const json& s) { return s["exec"] == "idle"; });
    start_program("rapid.ngc", "G21 G90\n" + before + "G0 X123.4 Y56.7 Z-8.9\nM2\n");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (status()["position"]["commanded"]["x"].get<double>() <= 0) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the rapid did not start";
      std::this_thread::sleep_for(milliseconds(1));
    }
    std::this_thread::sleep_for(milliseconds(delay_ms));
    json answer;
    // Answered once the path rests (an abort) or at once (a hold); never later than that.
    ASSERT_NO_THROW(answer = client_.call(stop, nullptr, 10000)) << stop << " was not answered";
    ASSERT_TRUE(answer.contains("result")) << answer.dump();
  }

  // The status once `motion` is `state`; fails after 10 s.
  json wait_motion(const std::string& state) {
    return wait_until([&](const json& s) { return s["motion"] == state; },
                      std::chrono::seconds(10));
  }

  void expect_at_target(const json& s) {
    EXPECT_DOUBLE_EQ(s["position"]["commanded"]["x"].get<double>(), kX);
    EXPECT_DOUBLE_EQ(s["position"]["commanded"]["y"].get<double>(), kY);
    EXPECT_DOUBLE_EQ(s["position"]["commanded"]["z"].get<double>(), kZ);
  }
};

TEST_F(HoldDaemon, AHoldDuringTheRapidsAccelerationRestsAndResumeEndsAtTheTarget) {
  ready_machine();
  for (const int delay : kDelaysMs) {
    SCOPED_TRACE(testing::Message() << "held " << delay << " ms after the start");
    ASSERT_NO_FATAL_FAILURE(rapid_then("program.pause", delay));
    json s = wait_motion("paused");
    ASSERT_EQ(s["motion"], "paused");
    EXPECT_EQ(s["velocity"], 0.0);
    const json held = s["position"]["commanded"];
    EXPECT_LT(held["x"].get<double>(), kX);
    std::this_thread::sleep_for(milliseconds(100));
    EXPECT_EQ(status()["position"]["commanded"], held);
    result_of(call("program.resume"));
    s = wait_until([](const json& st) { return st["exec"] == "idle"; });
    EXPECT_EQ(s["program"]["result"], "done");
    expect_at_target(s);
  }
}

TEST_F(HoldDaemon, AnAbortDuringTheRapidsAccelerationIsAnsweredAndTakesMDI) {
  ready_machine();
  for (const int delay : kDelaysMs) {
    SCOPED_TRACE(testing::Message() << "aborted " << delay << " ms after the start");
    ASSERT_NO_FATAL_FAILURE(rapid_then("program.abort", delay));
    json s = status();
    EXPECT_EQ(s["motion"], "idle");
    EXPECT_EQ(s["exec"], "idle");
    EXPECT_EQ(s["velocity"], 0.0);
    EXPECT_EQ(s["program"]["result"], "aborted");
    EXPECT_LT(s["position"]["commanded"]["x"].get<double>(), kX);
    ASSERT_NO_FATAL_FAILURE(mdi("G0 X10 Y20 Z-1"));
    s = status();
    EXPECT_EQ(s["position"]["commanded"]["x"], 10.0);
    EXPECT_EQ(s["position"]["commanded"]["y"], 20.0);
  }
}

TEST_F(HoldDaemon, StopOnPauseStopsTheSpindleOnAHoldDuringTheRapidsAcceleration) {
  ASSERT_NO_FATAL_FAILURE(restart_with_spindle_keys("STOP_ON_PAUSE = 1\n"));
  ready_machine();
  for (const int delay : kDelaysMs) {
    SCOPED_TRACE(testing::Message() << "held " << delay << " ms after the start");
    ASSERT_NO_FATAL_FAILURE(rapid_then("program.pause", delay, "M3 S3000\n"));
    json s = wait_until(
        [](const json& st) {
          return st["motion"] == "paused" && st["spindle"]["enabled"] == false;
        },
        std::chrono::seconds(10));
    ASSERT_EQ(s["motion"], "paused");
    EXPECT_EQ(s["spindle"]["enabled"], false);
    EXPECT_EQ(s["spindle"]["commanded_rpm"], 0.0);
    result_of(call("program.resume"));
    // The spindle turns again before the path goes on; M2 stops it at the end.
    s = wait_until([](const json& st) { return st["spindle"]["enabled"] == true; },
                   std::chrono::seconds(10));
    EXPECT_EQ(s["spindle"]["direction"], 1);
    s = wait_until([](const json& st) { return st["exec"] == "idle"; });
    EXPECT_EQ(s["program"]["result"], "done");
    expect_at_target(s);
  }
}

}  // namespace
}  // namespace cncd::test
