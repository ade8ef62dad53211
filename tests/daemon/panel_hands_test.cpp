// The panel's other hands on the real daemon: buttons that must do nothing in estop or while
// the machine is off, machine on and reset from the panel, the override knobs, one hand on the
// machine at a time (the MPG, a client's jog, the panel's jog buttons), and a panel pressed
// hard while another client floods the daemon with status requests.
#include <atomic>
#include <cmath>
#include <thread>

#include <gtest/gtest.h>

#include "panel_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

TEST_F(PanelTest, ButtonsInEstopAndWhileOffDoNothingButResetAndMachineOn) {
  open_program("moves.ngc", "G21 G90 G0 X10\nM2\n");
  ASSERT_EQ(status()["state"], "estop");
  auto since = last_seq();
  for (const char* key : {"CYCLE_START", "FEED_HOLD", "STOP", "JOG_X_PLUS", "MACHINE_ON"}) {
    SCOPED_TRACE(key);
    ASSERT_NO_FATAL_FAILURE(press(key));
  }
  json s = status();
  EXPECT_EQ(s["state"], "estop");
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_FALSE(panel_event(since, "CYCLE_START ignored: the machine is in estop").is_null());
  EXPECT_FALSE(panel_event(since, "MACHINE_ON refused").is_null());
  EXPECT_EQ(s["panel"]["lights"]["LIGHT_RED"], true);

  ASSERT_NO_FATAL_FAILURE(press("RESET"));
  s = wait_until([](const json& st) { return st["state"] == "off"; });
  since = last_seq();
  for (const char* key : {"CYCLE_START", "STOP", "JOG_X_PLUS"}) {
    SCOPED_TRACE(key);
    ASSERT_NO_FATAL_FAILURE(press(key));
  }
  s = status();
  EXPECT_EQ(s["state"], "off");
  EXPECT_EQ(s["exec"], "idle");
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_FALSE(panel_event(since, "CYCLE_START ignored: the machine is off").is_null());

  ASSERT_NO_FATAL_FAILURE(press("MACHINE_ON"));
  wait_until([](const json& st) { return st["state"] == "on"; });
  EXPECT_FALSE(panel_event(since, "MACHINE_ON: machine.on").is_null());
}

TEST_F(PanelTest, TenEncoderCountsAtOnePercentTakeTheFeedOverrideTo110Percent) {
  ready_machine();
  EXPECT_EQ(status()["overrides"]["feed"], 1.0);
  ASSERT_NO_FATAL_FAILURE(set("feed_override_counts", 10));
  json s = wait_until([](const json& st) { return st["overrides"]["feed"] != 1.0; });
  EXPECT_NEAR(s["overrides"]["feed"].get<double>(), 1.1, 1e-9);
  // The planned feed with it: F600 (10 mm/s) cruises at 11 mm/s.
  start_program("feed.ngc", "G21 G90 G0 X0 Y0 Z0\nG1 X100 F600\nM2\n");
  s = wait_until([](const json& st) { return st["velocity"].get<double>() > 10.5; });
  EXPECT_NEAR(s["velocity"].get<double>(), 11.0, 1e-6);
  result_of(call("program.abort"));
  // Back down: counts the other way.
  ASSERT_NO_FATAL_FAILURE(set("feed_override_counts", -20));
  s = wait_until([](const json& st) { return st["overrides"]["feed"].get<double>() < 1.0; });
  EXPECT_NEAR(s["overrides"]["feed"].get<double>(), 0.8, 1e-9);
}

TEST_F(PanelTest, AnAnalogKnobAtHalfScaleGivesTheMidOverride) {
  ready_machine();
  // RAPID_OVERRIDE_ANALOG 0 .. 10 over the rapid override's 0 .. 1.
  const auto override_near = [](double ratio) {
    return [ratio](const json& st) {
      return std::abs(st["overrides"]["rapid"].get<double>() - ratio) < 1e-9;
    };
  };
  wait_until(override_near(1.0), std::chrono::seconds(10));
  ASSERT_NO_FATAL_FAILURE(set("rapid_override_analog", 5.0));
  wait_until(override_near(0.5), std::chrono::seconds(10));
  ASSERT_NO_FATAL_FAILURE(set("rapid_override_analog", 2.5));
  wait_until(override_near(0.25), std::chrono::seconds(10));
}

TEST_F(PanelTest, AClientJogWhileTheMpgMovesIsRefusedNamingTheMpg) {
  ready_machine();
  ASSERT_NO_FATAL_FAILURE(level("MPG_ENABLE", true));
  ASSERT_NO_FATAL_FAILURE(level("MPG_AXIS_X", true));
  ASSERT_NO_FATAL_FAILURE(level("MPG_STEP_100", true));
  // 2500 detents of 0.1 mm: 250 mm, over a second at 200 mm/s.
  ASSERT_NO_FATAL_FAILURE(set("mpg_counts", 250000));
  const json moving =
      wait_until([](const json& st) { return st["panel"]["mpg"]["jogging"] == true; });
  EXPECT_EQ(moving["manual_holder"],
            json({{"by", "the panel's MPG"}, {"panel", true}, {"axis", "X"}, {"joint", nullptr}}));
  const json answer = call("jog.start", {{"axis", "Y"}, {"velocity", 5}});
  ASSERT_EQ(error_code(answer), 1004) << answer.dump();
  EXPECT_NE(answer["error"]["message"].get<std::string>().find("the panel's MPG"),
            std::string::npos)
      << answer.dump();
  const json s = wait_until([](const json& st) { return st["panel"]["mpg"]["jogging"] == false; });
  EXPECT_EQ(commanded(s, "y"), 0.0);
  EXPECT_TRUE(s["manual_holder"].is_null());
}

// 400 counts at 100 a detent on the 0.01 mm step: X moves by exactly 0.04 mm; then a spin of
// 0.1 mm detents far past X's soft limit (300 mm) stops there.
TEST_F(PanelTest, TheMpgMovesItsStepsExactlyAndStopsAtTheSoftLimit) {
  ready_machine();
  ASSERT_NO_FATAL_FAILURE(level("MPG_ENABLE", true));
  ASSERT_NO_FATAL_FAILURE(level("MPG_AXIS_X", true));
  ASSERT_NO_FATAL_FAILURE(level("MPG_STEP_10", true));
  json s = status();
  EXPECT_EQ(s["panel"]["mpg"]["axis"], "X");
  EXPECT_EQ(s["panel"]["mpg"]["step"], 0.01);
  ASSERT_NO_FATAL_FAILURE(set("mpg_counts", 400));
  s = wait_until([](const json& st) {
    return st["panel"]["mpg"]["counts"] == 400 && st["motion"] == "idle" &&
           st["position"]["commanded"]["x"].get<double>() > 0;
  });
  EXPECT_NEAR(commanded(s, "x"), 0.04, 1e-9);
  EXPECT_EQ(commanded(s, "y"), 0.0);
  ASSERT_NO_FATAL_FAILURE(level("MPG_STEP_10", false));
  ASSERT_NO_FATAL_FAILURE(level("MPG_STEP_100", true));
  // 4000 detents of 0.1 mm: 400 mm asked, 300 mm allowed.
  ASSERT_NO_FATAL_FAILURE(set("mpg_counts", 400 + 400000));
  s = wait_until([](const json& st) {
    return st["panel"]["mpg"]["jogging"] == false && st["motion"] == "idle" &&
           st["position"]["commanded"]["x"].get<double>() > 299;
  });
  EXPECT_NEAR(commanded(s, "x"), 300.0, 1e-6);
  EXPECT_LE(commanded(s, "x"), 300.0);
}

TEST_F(PanelTest, AJogButtonWhileAClientJogsIsRefusedNamingTheClient) {
  ready_machine();
  result_of(call("jog.start", {{"axis", "Y"}, {"velocity", 2}}));
  const auto since = last_seq();
  ASSERT_NO_FATAL_FAILURE(level("JOG_X_PLUS", true));
  const json refused = panel_event(since, "JOG_X_PLUS: jog.start X: refused");
  ASSERT_FALSE(refused.is_null()) << events_since(since).dump();
  const std::string text = refused["message"];
  EXPECT_NE(text.find("pid "), std::string::npos) << text;
  EXPECT_NE(text.find("is jogging"), std::string::npos) << text;
  ASSERT_NO_FATAL_FAILURE(level("JOG_X_PLUS", false));
  result_of(call("jog.stop", {{"axis", "Y"}}));
  const json s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_EQ(commanded(s, "x"), 0.0);
  // And the other way round: the panel's button jogs, a client is refused naming it.
  ASSERT_NO_FATAL_FAILURE(level("JOG_X_PLUS", true));
  const json jogging = wait_until([](const json& st) { return st["motion"] == "jogging"; });
  EXPECT_EQ(jogging["manual_holder"], json({{"by", "the panel's JOG_X_PLUS button"},
                                            {"panel", true},
                                            {"axis", "X"},
                                            {"joint", nullptr}}));
  const json answer = call("jog.start", {{"axis", "Y"}, {"velocity", 2}});
  ASSERT_EQ(error_code(answer), 1004) << answer.dump();
  EXPECT_NE(answer["error"]["message"].get<std::string>().find("the panel's JOG_X_PLUS"),
            std::string::npos);
  ASSERT_NO_FATAL_FAILURE(level("JOG_X_PLUS", false));
  const json rest = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_GT(commanded(rest, "x"), 0.0);
}

// G0 X123.4 Y56.7: 200 mm/s reached after 100 ms; the hold is pressed as soon as X moves.
TEST_F(PanelTest, AHoldPressedDuringTheRapidsAccelerationRestsAndResumeEndsThere) {
  ready_machine();
  open_program("rapid.ngc", "G21 G90 G0 X0 Y0 Z0\nG0 X123.4 Y56.7\nM2\n");
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (commanded(status(), "x") <= 0)
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the rapid did not start";
  ASSERT_NO_FATAL_FAILURE(set("feed_hold", 1));
  json s = wait_until([](const json& st) { return st["motion"] == "paused"; });
  EXPECT_EQ(s["velocity"], 0.0);
  const double held = commanded(s, "x");
  EXPECT_LT(held, 123.4);
  ASSERT_NO_FATAL_FAILURE(set("feed_hold", 0));
  EXPECT_EQ(commanded(status(), "x"), held);
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 123.4);
  EXPECT_DOUBLE_EQ(commanded(s, "y"), 56.7);
}

// Many holds and resumes from the panel, each acted on, while a second client asks for the
// status as fast as it can; the first hold comes during the rapid's acceleration.
TEST_F(PanelTest, EveryPressActsWhileAnotherClientFloodsStatusRequests) {
  ready_machine();
  std::atomic<bool> stop{false};
  std::atomic<int> answered{0};
  std::thread flood([&] {
    daemon::Client other;
    if (!other.connect(daemon_.socket()).empty()) return;
    while (!stop.load()) {
      if (other.call("status.get", nullptr, 30000).contains("result")) ++answered;
    }
  });
  open_program("far.ngc", "G21 G90 G0 X0 Y0 Z0\nG0 X290 Y190\nM2\n");
  const auto since = last_seq();
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  wait_until([&](const json& s) { return commanded(s, "x") > 0; });
  constexpr int kRounds = 12;
  for (int round = 0; round < kRounds; ++round) {
    SCOPED_TRACE(testing::Message() << "round " << round);
    ASSERT_NO_FATAL_FAILURE(press("FEED_HOLD"));
    const json held =
        wait_until([](const json& s) { return s["motion"] == "paused" || s["exec"] == "idle"; });
    if (held["exec"] == "idle") break;  // the rapid ended before the hold
    ASSERT_EQ(held["exec"], "paused");
    ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
    const json s = wait_until([](const json& st) { return st["exec"] != "paused"; });
    if (s["exec"] == "idle") break;  // the rapid ended before the next hold
  }
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  stop = true;
  flood.join();
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 290.0);
  EXPECT_DOUBLE_EQ(commanded(s, "y"), 190.0);
  int holds = 0;
  int resumes = 0;
  for (const auto& e : events_since(since)) {
    if (e.value("by", "") != "panel") continue;
    if (e["message"] == "FEED_HOLD: program.pause") ++holds;
    if (e["message"] == "CYCLE_START: program.resume") ++resumes;
  }
  EXPECT_GE(holds, 1);
  EXPECT_EQ(holds, resumes);
  EXPECT_GT(answered.load(), 0);
}

}  // namespace
}  // namespace cncd::test
