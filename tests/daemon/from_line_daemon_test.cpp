// Run from a line on the real daemon: a 3D finishing program run from line 200 ends as the
// whole program does, with the spindle and coolant on before the line's moves, and the way to
// the line's start rises before it moves over; under cutter compensation the way leads to the
// compensated point.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// A 3D_Chips-style surface pass: spindle, coolant, then short moves in X, Y and Z.
std::string surface_program(int moves) {
  std::string text = "G21 G90 G64 P0.01\nS9000 M3\nM8\nG0 Z5\nG0 X1 Y1\nG1 Z-1 F3000\n";
  for (int i = 1; i <= moves; ++i) {
    const double x = 1 + 0.4 * i;
    const double y = 1 + 3 * std::sin(i * 0.05);
    const double z = -1 - 0.8 * std::sin(i * 0.11);
    char line[96];
    std::snprintf(line, sizeof line, "G1 X%.3f Y%.3f Z%.3f\n", x, y, z);
    text += line;
  }
  return text + "G0 Z5\nM5 M9\nM2\n";
}

// What a run leaves: where the machine stands, its modes, spindle, coolant and offsets.
json end_state(const json& s) {
  return {{"position", s["position"]["commanded"]},
          {"gcodes", s["gcodes"]},
          {"mcodes", s["mcodes"]},
          {"spindle", s["spindle"]["direction"]},
          {"coolant", s["coolant"]},
          {"offsets", s["offsets"]},
          {"result", s["program"]["result"]}};
}

struct Xyz {
  double x = 0, y = 0, z = 0;
};

class FromLineTest : public MachineTest {
 protected:
  // Runs `program` whole, then from `line`, calling sample(status, position, over) at each
  // status of the second run, `over` once X and Y have stood at `start`. Before that X and Y
  // move only at the safe height ([AXIS_Z] MAX_LIMIT 50). Returns the whole run's status and
  // the last one's.
  template <typename Sample>
  std::pair<json, json> run_whole_then_from(const std::string& program, int line, double x0,
                                            double y0, Sample sample) {
    ready_machine();
    result_of(call("program.open", {{"path", dir_.write("prog.ngc", program).string()}}));
    result_of(call("program.run"));
    const json whole = wait_until([](const json& s) { return s["exec"] == "idle"; });
    EXPECT_EQ(whole["program"]["result"], "done") << whole.dump();
    const json from = whole["position"]["commanded"];
    result_of(call("program.run", {{"from_line", line}}));
    bool over = false;
    json s;
    for (;;) {
      s = status();
      const json& at = s["position"]["commanded"];
      const Xyz p{at["x"], at["y"], at["z"]};
      const bool at_from =
          std::hypot(p.x - from["x"].get<double>(), p.y - from["y"].get<double>()) < 1e-6;
      if (std::hypot(p.x - x0, p.y - y0) < 1e-6) over = true;
      if (!over && !at_from) {
        EXPECT_NEAR(p.z, 50.0, 1e-6) << "X" << p.x << " Y" << p.y;
      }
      sample(s, p, over);
      if (s["exec"] == "idle") break;
    }
    EXPECT_TRUE(over);
    EXPECT_EQ(end_state(s), end_state(whole)) << s.dump();
    return {whole, s};
  }
};

TEST_F(FromLineTest, RunFromLine200EndsAsTheWholeProgramAndRisesBeforeItMovesOver) {
  // Line 200 is the move to X 1 + 0.4 x 194; the moves before it end at move 193's point.
  const auto rounded = [](double v) { return std::round(v * 1000) / 1000; };
  const double x0 = rounded(1 + 0.4 * 193), y0 = rounded(1 + 3 * std::sin(193 * 0.05)),
               z0 = rounded(-1 - 0.8 * std::sin(193 * 0.11));
  bool line_moved = false;
  double lowest_over_start = 1e9;
  run_whole_then_from(surface_program(260), 200, x0, y0, [&](const json& s, Xyz p, bool over) {
    const bool at_start = std::hypot(p.x - x0, p.y - y0) < 1e-6;
    if (at_start && !line_moved) lowest_over_start = std::min(lowest_over_start, p.z);
    if (over && !at_start && !line_moved) {
      line_moved = true;
      // The line's own moves start with the spindle and coolant as the lines before left them,
      // and from the start point the lines before reached.
      EXPECT_EQ(s["spindle"]["direction"], 1) << s.dump();
      EXPECT_EQ(s["coolant"]["flood"], true) << s.dump();
    }
  });
  EXPECT_GE(lowest_over_start, z0 - 1e-6);  // down to the start, never past it
}

// Under G41.1 (a 2 mm tool, left of the path) a run from line 6 starts where the compensated
// path reaches the line: line 5's move, on X9, ends at X9 Y9 (the inside corner), and line 6
// runs on from there along Y9. Line 5 is not cut again; the run ends as the whole one does.
TEST_F(FromLineTest, RunFromALineUnderCutterCompensationStartsAtTheCompensatedPoint) {
  run_whole_then_from(
      "G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\nG1 X10 Y10\nG1 X0 Y10\n"
      "G1 X0 Y0\nG40 G1 X-5 Y-5\nG0 Z5\nM2\n",
      6, 9, 9, [](const json&, Xyz p, bool over) {
        // Cutting (below Z0) only on lines 6 and on: Y9 from X9 back, X1, and the way out.
        if (p.z < 0) {
          EXPECT_TRUE(over) << "X" << p.x << " Y" << p.y << " Z" << p.z;
          // Line 5 runs on X9 from Y1 to Y9 (corners blend within the path tolerance).
          EXPECT_FALSE(p.x > 8.5 && p.y < 8.5) << "line 5 cut again at X" << p.x << " Y" << p.y;
        }
      });
}

// An M0 on the line a run starts from under cutter compensation stops the machine there, as in
// the whole run: the M0 puts out line 5's move (ending at X9 Y10, the next move not yet read),
// the way leads there, and the machine waits for the operator before line 7.
TEST_F(MachineTest, AnM0OnTheStartLineUnderCutterCompensationStops) {
  ready_machine();
  const auto program = dir_.write("m0.ngc",
                                  "G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\n"
                                  "G1 X10 Y10\nM0\nG1 X0 Y10\nG1 X0 Y0\nG40 G1 X-5 Y-5\n"
                                  "G0 Z5\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  for (const json& params : {json::object(), json{{"from_line", 6}}}) {
    result_of(call("program.run", params));
    json s = wait_until([](const json& st) { return st["exec"] != "running"; });
    ASSERT_EQ(s["exec"], "paused") << params.dump() << ": " << s.dump();
    EXPECT_EQ(s["motion"], "idle");
    EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 9.0, 1e-9);
    EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 10.0, 1e-9);
    EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), -1.0, 1e-9);
    result_of(call("program.resume"));
    s = wait_until([](const json& st) { return st["exec"] == "idle"; });
    EXPECT_EQ(s["program"]["result"], "done") << s.dump();
    EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), -5.0, 1e-9);
    EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), 5.0, 1e-9);
  }
}

}  // namespace
}  // namespace cncd::test
