// G33.1 and G33 through the real daemon on the example sim machine: status shows the tap's
// phases while it runs, the tap ends where it started with the spindle turning forward again,
// a feed hold lets the tap come out before the machine holds (and one during a thread says it
// waits for the thread's end), the next feed waits until the spindle is back at speed, and a
// thread the axis cannot follow is refused at open.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

class SyncDaemon : public MachineTest {
 protected:
  static double z(const nlohmann::json& s) { return s["position"]["commanded"]["z"].get<double>(); }
};

TEST_F(SyncDaemon, RigidTapRunsShowsItsPhasesAndRestoresTheSpindle) {
  ready_machine();
  start_program("tap.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33.1 Z-10 K1.25\nG1 X20 F600\nM2\n");
  std::set<std::string> phases;
  double deepest = 1e9;
  bool forward_again = false;
  const auto s = wait_until([&](const nlohmann::json& st) {
    if (!st["sync"].is_null()) {
      EXPECT_EQ(st["sync"]["mode"], "tap");
      EXPECT_EQ(st["sync"]["per_rev"], 1.25);
      phases.insert(st["sync"]["phase"].get<std::string>());
    }
    deepest = std::min(deepest, z(st));
    // The feed to X20 runs with the spindle forward at speed again.
    const double x = st["position"]["commanded"]["x"].get<double>();
    if (x > 10.001 && x < 19.999) {
      forward_again = st["spindle"]["direction"] == 1 && st["spindle"]["at_speed"] == true;
    }
    return st["exec"] == "idle" && st["program"]["result"] != "";
  });
  ASSERT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_TRUE(phases.count("tapping_in")) << ::testing::PrintToString(phases);
  EXPECT_TRUE(phases.count("tapping_out")) << ::testing::PrintToString(phases);
  EXPECT_LT(deepest, -5);  // sampled on the way down
  EXPECT_GE(deepest, -10.002);
  EXPECT_NEAR(z(s), 5, 1e-9);
  EXPECT_TRUE(forward_again);
  EXPECT_TRUE(s["sync"].is_null());
}

TEST_F(SyncDaemon, FeedHoldDuringATapHoldsOnlyOnceTheTapIsOut) {
  ready_machine();
  start_program("tap.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33.1 Z-20 K1.25\nG0 X30\nM2\n");
  wait_until([](const nlohmann::json& st) {
    return !st["sync"].is_null() && st["sync"]["phase"] == "tapping_in" &&
           st["position"]["commanded"]["z"].get<double>() < 0;
  });
  result_of(call("program.pause"));
  const auto held = wait_until([](const nlohmann::json& st) { return st["motion"] == "paused"; });
  EXPECT_NEAR(z(held), 5, 1e-9);  // out of the hole
  EXPECT_NEAR(held["position"]["commanded"]["x"].get<double>(), 10, 1e-9);
  result_of(call("program.resume"));
  const auto s = wait_until([](const nlohmann::json& st) {
    return st["exec"] == "idle" && st["program"]["result"] != "";
  });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 30, 1e-9);
}

TEST_F(SyncDaemon, ThreadRunsToItsEnd) {
  ready_machine();
  start_program("thread.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33 Z-10 K1.5\nG0 Z20\nM2\n");
  bool following = false;
  const auto s = wait_until([&](const nlohmann::json& st) {
    if (!st["sync"].is_null() && st["sync"]["phase"] == "following") {
      following = true;
      EXPECT_EQ(st["sync"]["mode"], "thread");
    }
    return st["exec"] == "idle" && st["program"]["result"] != "";
  });
  ASSERT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_TRUE(following);
  EXPECT_NEAR(z(s), 20, 1e-9);
}

// A feed hold cannot stop a thread midway: the answer and status say that it takes effect at
// the thread's end, and it does.
TEST_F(SyncDaemon, FeedHoldDuringAThreadSaysItWaitsForTheThreadsEnd) {
  ready_machine();
  start_program("thread.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33 Z-40 K1.5\nG0 Z20\nM2\n");
  wait_until([](const nlohmann::json& st) {
    return !st["sync"].is_null() && st["sync"]["phase"] == "following" && z(st) < 0;
  });
  auto answer = result_of(call("program.pause"));  // not const: a missing key reads as null
  EXPECT_EQ(answer["ok"], true);
  EXPECT_EQ(answer["waits_for"], "thread_end") << answer.dump();
  EXPECT_EQ(answer["line"], 4) << answer.dump();
  EXPECT_NE(answer.value("message", "").find("thread (G33)"), std::string::npos) << answer.dump();
  auto pausing = wait_until([](const nlohmann::json& st) {
    return st["motion"] == "pausing" || st["motion"] == "paused";
  });
  if (pausing["motion"] == "pausing") {
    EXPECT_EQ(pausing["pause_wait"]["kind"], "thread_end") << pausing.dump();
    EXPECT_EQ(pausing["pause_wait"]["line"], 4);
  }
  auto held = wait_until([](const nlohmann::json& st) { return st["motion"] == "paused"; });
  EXPECT_NEAR(z(held), -40, 1e-9);  // the thread ran to its end
  EXPECT_TRUE(held["pause_wait"].is_null()) << held.dump();
  result_of(call("program.resume"));
  const auto s = wait_until([](const nlohmann::json& st) {
    return st["exec"] == "idle" && st["program"]["result"] != "";
  });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
}

TEST_F(SyncDaemon, CncctlPauseDuringAThreadPrintsThatTheHoldWaitsForItsEnd) {
  ready_machine();
  start_program("thread.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S600\nG33 Z-40 K1.5\nG0 Z20\nM2\n");
  wait_until([](const nlohmann::json& st) {
    return !st["sync"].is_null() && st["sync"]["phase"] == "following" && z(st) < 0;
  });
  const auto paused = cncctl({"pause"});
  EXPECT_EQ(paused.exit_status, 0) << paused.err;
  EXPECT_EQ(paused.out,
            "the feed hold takes effect once the thread (G33) has reached its end (line 4)\n");
  const auto held = wait_until([](const nlohmann::json& st) { return st["motion"] == "paused"; });
  EXPECT_NEAR(z(held), -40, 1e-9);
}

// A thread whose pitch at its speed is more than the axis can follow is refused at open.
TEST_F(SyncDaemon, AThreadTheAxisCannotFollowIsRefusedAtOpen) {
  ready_machine();
  const auto program =
      dir_.write("fast.ngc", "G21 G90\nG0 X10 Y10 Z5\nM3 S6000\nG33 Z-10 K100\nM2\n");
  const auto opened = call("program.open", {{"path", program.string()}});
  ASSERT_TRUE(opened.contains("error")) << opened.dump();
  EXPECT_EQ(opened["error"]["code"], 1003);
  const std::string message = opened["error"].value("message", "");
  EXPECT_NE(message.find("fast.ngc:4"), std::string::npos) << message;
  EXPECT_NE(message.find("G33 at S6000 with 100 mm per revolution needs Z at 10000 mm/s; "
                         "[AXIS_Z] MAX_VELOCITY is 100 mm/s"),
            std::string::npos)
      << message;
}

// G96: the spindle's speed follows X (program X0 the spindle's axis) within D; G97 turns at S.
TEST_F(SyncDaemon, ConstantSurfaceSpeedFollowsX) {
  ready_machine();
  mdi("G21 G90 G0 X40 Y10 Z5");
  mdi("G96 D1000 S100 M3");
  auto s = wait_until([](const nlohmann::json& st) { return st["spindle"]["at_speed"] == true; });
  // 100 m/min at 40 mm from the axis: 100000 / (2 pi 40) = 397.9 rpm.
  EXPECT_NEAR(s["spindle"]["commanded_rpm"].get<double>(), 397.887, 0.01) << s["spindle"].dump();
  EXPECT_EQ(s["spindle"]["css"]["max_rpm"], 1000.0);
  EXPECT_EQ(s["spindle"]["programmed_speed"], 100.0);
  mdi("G1 X20 F600");
  s = wait_until([](const nlohmann::json& st) { return st["motion"] == "idle"; });
  EXPECT_NEAR(s["spindle"]["commanded_rpm"].get<double>(), 795.775, 0.01);
  mdi("G0 X5");
  s = wait_until([](const nlohmann::json& st) { return st["motion"] == "idle"; });
  EXPECT_NEAR(s["spindle"]["commanded_rpm"].get<double>(), 1000, 1e-9);  // D
  mdi("G97 S500");
  s = status();
  EXPECT_NEAR(s["spindle"]["commanded_rpm"].get<double>(), 500, 1e-9);
  EXPECT_TRUE(s["spindle"]["css"].is_null());
}

}  // namespace
}  // namespace cncd::test
