// The panel runs programs on the real daemon: cycle start runs the open program, feed hold
// pauses it and cycle start resumes it, single block steps it, the optional stop and block
// delete switches change how it is read, and the door holds it, stops the spindle and the
// coolant at rest, refuses to start until closed, and its resume waits for the spindle's speed.
#include <gtest/gtest.h>

#include "panel_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

const std::string kSeedProgram = std::string(CNCD_SOURCE_DIR) + "/examples/g81_example1.ngc";

TEST_F(PanelTest, CycleStartRunsTheOpenG81ProgramToX4Y5Z3) {
  ready_machine();
  result_of(call("program.open", {{"path", kSeedProgram}}));
  const auto since = last_seq();
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  const json event = panel_event(since, "CYCLE_START: program.run");
  EXPECT_FALSE(event.is_null()) << events_since(since).dump();
  const json s = wait_until(
      [](const json& st) { return st["exec"] == "idle" && st["program"]["result"] != ""; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 4.0);
  EXPECT_DOUBLE_EQ(commanded(s, "y"), 5.0);
  EXPECT_DOUBLE_EQ(commanded(s, "z"), 3.0);
}

TEST_F(PanelTest, CycleStartWithoutAProgramIsRefusedWithTheReason) {
  ready_machine();
  const auto since = last_seq();
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  const json event = panel_event(since, "CYCLE_START refused");
  ASSERT_FALSE(event.is_null()) << events_since(since).dump();
  EXPECT_EQ(event["message"], "CYCLE_START refused: no program is open");
  EXPECT_EQ(status()["exec"], "idle");
}

TEST_F(PanelTest, FeedHoldMidMovePausesAndCycleStartResumes) {
  ready_machine();
  open_program("long.ngc", "G21 G90 G0 X0 Y0 Z0\nG1 X200 F3000\nM2\n");
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  wait_until([&](const json& s) { return commanded(s, "x") > 5; });
  ASSERT_NO_FATAL_FAILURE(press("FEED_HOLD"));
  json s = wait_until([](const json& st) { return st["motion"] == "paused"; });
  EXPECT_EQ(s["exec"], "paused");
  EXPECT_EQ(s["velocity"], 0.0);
  const double held = commanded(s, "x");
  EXPECT_LT(held, 200.0);
  EXPECT_EQ(s["panel"]["lights"]["LAMP_FEED_HOLD"], true);
  EXPECT_EQ(s["panel"]["lights"]["LIGHT_AMBER"], true);
  EXPECT_EQ(s["panel"]["lights"]["LIGHT_GREEN"], false);
  EXPECT_EQ(commanded(status(), "x"), held);
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 200.0);
  EXPECT_EQ(s["panel"]["lights"]["LAMP_FEED_HOLD"], false);
}

TEST_F(PanelTest, SingleBlockStopsAfterEachBlock) {
  ready_machine();
  open_program("blocks.ngc", "G21 G90\nG0 X10\nG0 Y20\nG0 Z-5\nM2\n");
  ASSERT_NO_FATAL_FAILURE(level("SINGLE_BLOCK", true));
  const double ends[][3] = {{0, 0, 0}, {10, 0, 0}, {10, 20, 0}, {10, 20, -5}};
  for (int block = 0; block < 4; ++block) {
    SCOPED_TRACE(testing::Message() << "press " << block + 1);
    ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
    const json s = wait_until([&](const json& st) {
      return st["exec"] == "paused" && st["motion"] == "idle" && st["program"]["line"] == block + 1;
    });
    EXPECT_DOUBLE_EQ(commanded(s, "x"), ends[block][0]);
    EXPECT_DOUBLE_EQ(commanded(s, "y"), ends[block][1]);
    EXPECT_DOUBLE_EQ(commanded(s, "z"), ends[block][2]);
  }
  ASSERT_NO_FATAL_FAILURE(level("SINGLE_BLOCK", false));
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
}

TEST_F(PanelTest, TheOptionalStopSwitchDecidesWhetherM1Stops) {
  ready_machine();
  open_program("m1.ngc", "G21 G90 G0 X0 Y0 Z0\nG0 X10\nM1\nG0 X20\nM2\n");
  ASSERT_NO_FATAL_FAILURE(level("OPTIONAL_STOP", false));
  EXPECT_EQ(status()["panel"]["optional_stop"], false);
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  json s = wait_until([](const json& st) { return st["exec"] != "running"; });
  EXPECT_EQ(s["exec"], "idle") << "M1 stopped with the switch off";
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 20.0);

  ASSERT_NO_FATAL_FAILURE(level("OPTIONAL_STOP", true));
  EXPECT_EQ(status()["panel"]["optional_stop"], true);
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  s = wait_until([](const json& st) { return st["exec"] == "paused"; });
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 10.0);
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 20.0);
}

TEST_F(PanelTest, BlockDeleteSkipsSlashLinesWhileOn) {
  ready_machine();
  open_program("slash.ngc", "G21 G90 G0 X0 Y0 Z0\nG0 X10\n/G0 Y30\nG0 Z-5\nM2\n");
  ASSERT_NO_FATAL_FAILURE(level("BLOCK_DELETE", true));
  EXPECT_EQ(status()["panel"]["block_delete"], true);
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "y"), 0.0);
  EXPECT_DOUBLE_EQ(commanded(s, "z"), -5.0);

  ASSERT_NO_FATAL_FAILURE(level("BLOCK_DELETE", false));
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_DOUBLE_EQ(commanded(s, "y"), 30.0);
}

TEST_F(PanelTest, TheDoorHoldsStopsTheSpindleAndResumeWaitsForItsSpeed) {
  ready_machine();
  // 6000 rpm at 6000 rpm/s: a second to come up to speed from rest.
  open_program("cut.ngc", "G21 G90 G0 X0 Y0 Z0\nM3 S6000\nM8\nG1 X150 F1200\nM2\n");
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  wait_until([&](const json& s) { return commanded(s, "x") > 5; });
  const auto since = last_seq();
  ASSERT_NO_FATAL_FAILURE(level("DOOR", true));
  // Held, then the spindle stops (coming to rest at its ACCELERATION) and the coolant goes off.
  json s = wait_until([](const json& st) {
    return st["motion"] == "paused" && st["spindle"]["enabled"] == false &&
           st["spindle"]["actual_rpm"] == 0.0 && st["coolant"]["flood"] == false;
  });
  EXPECT_EQ(s["exec"], "paused");
  EXPECT_EQ(s["panel"]["door"], true);
  const double held = commanded(s, "x");
  EXPECT_LT(held, 150.0);
  EXPECT_FALSE(panel_event(since, "DOOR opened: program.pause").is_null());

  // Refused while open, from the panel and from a client.
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  const json refused = panel_event(since, "CYCLE_START refused");
  ASSERT_FALSE(refused.is_null());
  EXPECT_EQ(refused["message"], "CYCLE_START refused: the door is open: close it first");
  const json resume = call("program.resume");
  EXPECT_EQ(error_code(resume), 1001);
  s = status();
  EXPECT_EQ(s["exec"], "paused");
  EXPECT_EQ(s["spindle"]["enabled"], false);
  EXPECT_EQ(commanded(s, "x"), held);

  ASSERT_NO_FATAL_FAILURE(level("DOOR", false));
  ASSERT_NO_FATAL_FAILURE(press("CYCLE_START"));
  // Until the spindle is at speed the path stays where it was held.
  bool saw_spin_up = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (;;) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << status().dump();
    s = status();
    if (commanded(s, "x") != held) break;
    if (s["spindle"]["enabled"] == true && s["spindle"]["at_speed"] == false) saw_spin_up = true;
  }
  EXPECT_TRUE(saw_spin_up) << "the path moved on before the spindle came up to speed";
  EXPECT_EQ(s["spindle"]["at_speed"], true) << s.dump();
  EXPECT_EQ(s["coolant"]["flood"], true);
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_DOUBLE_EQ(commanded(s, "x"), 150.0);
}

}  // namespace
}  // namespace cncd::test
