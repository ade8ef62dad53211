// status.get beyond positions: work coordinates, offsets, tool, active codes, progress.
#include <algorithm>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

bool has_code(const json& codes, const std::string& code) {
  return std::find(codes.begin(), codes.end(), code) != codes.end();
}

TEST_F(MachineTest, WorkPositionFollowsOffsetsAndToolLength) {
  ready_machine();
  mdi("G10 L2 P1 X10 Y20 Z5");
  mdi("G0 X1 Y2 Z3");
  json s = status();
  EXPECT_EQ(s["position"]["commanded"]["x"], 11.0);
  EXPECT_EQ(s["position"]["commanded"]["y"], 22.0);
  EXPECT_EQ(s["position"]["commanded"]["z"], 8.0);
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 1.0, 1e-9);
  // The feedback is read before the period's new command: read in the very period the move
  // ended, the actual position is still one period's step (here 0.001 mm) short.
  EXPECT_NEAR(s["work_position"]["actual"]["y"].get<double>(), 2.0, 0.01);
  EXPECT_EQ(s["offsets"]["coord_system"], "G54");
  EXPECT_EQ(s["offsets"]["g5x"]["y"], 20.0);

  // G92 shifts the work position again; tool 2 (Z+10 in sim_mm.tbl) with G43 too.
  mdi("G92 X0");
  mdi("M61 Q2 G43");  // the tool is in the spindle: no change to wait for
  s = status();
  EXPECT_EQ(s["offsets"]["g92"]["x"], 1.0);
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(s["tool"]["number"], 2);
  EXPECT_EQ(s["tool"]["length_offset"]["z"], 10.0);
  EXPECT_EQ(s["tool"]["entry"]["diameter"], 3.0);
  EXPECT_EQ(s["tool"]["entry"]["comment"], "3 mm drill");
  EXPECT_NEAR(s["work_position"]["commanded"]["z"].get<double>(), 8.0 - 5.0 - 10.0, 1e-9);
  EXPECT_TRUE(has_code(s["gcodes"], "G43")) << s["gcodes"];
  EXPECT_TRUE(has_code(s["gcodes"], "G92.3")) << s["gcodes"];

  // Another coordinate system: G55's origin is zero in the example parameters.
  mdi("G55");
  s = status();
  EXPECT_EQ(s["offsets"]["coord_system"], "G55");
  EXPECT_EQ(s["offsets"]["index"], 2);
  EXPECT_TRUE(has_code(s["gcodes"], "G55"));
}

TEST_F(MachineTest, ActiveCodesSpindleAndCoolant) {
  ready_machine();
  json s = status();
  // RS274NGC_STARTUP_CODE = G17 G21 G40 G49 G54 G80 G90 G94 runs with the first block.
  mdi("G91 G1 F600 X1");
  mdi("M3 S1200 M8");
  s = status();
  for (const char* code : {"G1", "G17", "G40", "G21", "G91", "G94", "G54", "G49", "G64"}) {
    EXPECT_TRUE(has_code(s["gcodes"], code)) << code << " in " << s["gcodes"];
  }
  EXPECT_FALSE(has_code(s["gcodes"], "G90"));
  for (const char* code : {"M3", "M8", "M48"}) {
    EXPECT_TRUE(has_code(s["mcodes"], code)) << code << " in " << s["mcodes"];
  }
  EXPECT_EQ(s["spindle"]["direction"], 1);
  EXPECT_EQ(s["spindle"]["speed"], 1200.0);
  EXPECT_EQ(s["coolant"]["flood"], true);
  EXPECT_EQ(s["coolant"]["mist"], false);
  EXPECT_EQ(s["feed_rate"], 600.0);
  mdi("M5 M9");
  s = status();
  EXPECT_TRUE(has_code(s["mcodes"], "M5"));
  EXPECT_TRUE(has_code(s["mcodes"], "M9"));
  EXPECT_EQ(s["coolant"]["flood"], false);
}

TEST_F(MachineTest, ProgressAndElapsedTime) {
  ready_machine();
  const auto program = dir_.write("slow.ngc", "G21 G90\nG1 F1200 X20\nG1 X0\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  json s = status();
  EXPECT_EQ(s["program"]["total_lines"], 4);
  EXPECT_EQ(s["program"]["progress"], 0.0);
  result_of(call("program.run"));
  s = wait_until([](const json& st) { return st["program"]["line"] == 3; });
  EXPECT_EQ(s["program"]["progress"], 0.75);
  EXPECT_GT(s["program"]["elapsed_s"].get<double>(), 0.0);
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_EQ(s["program"]["progress"], 1.0);
  EXPECT_GT(s["program"]["elapsed_s"].get<double>(), 1.0);  // 40 mm at 20 mm/s
  // The run took the time estimated at program.open; nothing remains.
  EXPECT_EQ(s["program"]["remaining_s"], 0.0);
  // On the servo clock: wall time also counts periods a stalled servo thread skipped. The
  // servo clock still counts the daemon's loop noticing the start and the end of the run: up to
  // tens of ms on a loaded machine under the sanitizers.
  EXPECT_NEAR(s["program"]["estimated_s"].get<double>(), s["program"]["motion_s"].get<double>(),
              0.1);
  // Ahead of wall time only by a stalled servo thread catching up: at most 10 periods.
  EXPECT_GE(s["program"]["elapsed_s"].get<double>() + 0.012,
            s["program"]["motion_s"].get<double>());
}

TEST_F(MachineTest, NewFieldsCanBeAskedForAndSubscribedTo) {
  const json only = result_of(call("status.get", {{"fields", {"work_position", "offsets"}}}));
  EXPECT_EQ(only.size(), 2u);
  EXPECT_TRUE(only["work_position"]["commanded"].contains("x"));
  EXPECT_EQ(only["offsets"]["coord_system"], "G54");
  const json sub = call("status.subscribe", {{"interval_ms", 20}, {"fields", {"gcodes", "tool"}}});
  ASSERT_TRUE(sub.contains("result")) << sub.dump();
  const json update = json::parse(client_.read_line());
  EXPECT_EQ(update["method"], "status.update");
  EXPECT_TRUE(update["params"]["changed"].contains("gcodes"));
  EXPECT_EQ(update["params"]["changed"]["tool"]["number"], 0);
  EXPECT_FALSE(update["params"]["changed"].contains("state"));
}

}  // namespace
}  // namespace cncd::test
