// Run from a line on the real daemon: a 3D finishing program run from line 200 ends as the
// whole program does, with the spindle and coolant on before the line's moves, and the way to
// the line's start rises before it moves over; under cutter compensation the way leads to the
// compensated point.
#include <algorithm>
#include <cmath>
#include <string>
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

TEST_F(MachineTest, RunFromLine200EndsAsTheWholeProgramAndRisesBeforeItMovesOver) {
  ready_machine();
  const auto program = dir_.write("surface.ngc", surface_program(260));
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const json whole = wait_until([](const json& s) { return s["exec"] == "idle"; });
  ASSERT_EQ(whole["program"]["result"], "done") << whole.dump();
  // Line 200 is the move to X 1 + 0.4 x 194; the moves before it end at move 193's point.
  const double x0 = 1 + 0.4 * 193, y0 = 1 + 3 * std::sin(193 * 0.05),
               z0 = -1 - 0.8 * std::sin(193 * 0.11);
  const auto rounded = [](double v) { return std::round(v * 1000) / 1000; };
  const json from = whole["position"]["commanded"];
  result_of(call("program.run", {{"from_line", 200}}));
  bool over = false, line_moved = false;
  double lowest_over_start = 1e9;
  json s;
  for (;;) {
    s = status();
    const double x = s["position"]["commanded"]["x"], y = s["position"]["commanded"]["y"],
                 z = s["position"]["commanded"]["z"];
    const bool at_from =
        std::hypot(x - from["x"].get<double>(), y - from["y"].get<double>()) < 1e-6;
    const bool at_start = std::hypot(x - rounded(x0), y - rounded(y0)) < 1e-6;
    if (at_start) over = true;
    if (at_start && !line_moved) lowest_over_start = std::min(lowest_over_start, z);
    if (!over && !at_from) {
      // X and Y move only at the safe height ([AXIS_Z] MAX_LIMIT 50).
      EXPECT_NEAR(z, 50.0, 1e-6) << "X" << x << " Y" << y;
    }
    if (over && !at_start && !line_moved) {
      line_moved = true;
      // The line's own moves start with the spindle and coolant as the lines before left them,
      // and from the start point the lines before reached.
      EXPECT_EQ(s["spindle"]["direction"], 1) << s.dump();
      EXPECT_EQ(s["coolant"]["flood"], true) << s.dump();
    }
    if (s["exec"] == "idle") break;
  }
  EXPECT_TRUE(over);
  EXPECT_EQ(end_state(s), end_state(whole)) << s.dump();
  EXPECT_GE(lowest_over_start, rounded(z0) - 1e-6);  // down to the start, never past it
}

// Under G41.1 (a 2 mm tool, left of the path) a run from line 6 starts where the compensated
// path reaches the line: line 5's move, on X9, ends at X9 Y9 (the inside corner), and line 6
// runs on from there along Y9. Line 5 is not cut again; the run ends as the whole one does.
TEST_F(MachineTest, RunFromALineUnderCutterCompensationStartsAtTheCompensatedPoint) {
  ready_machine();
  const auto program =
      dir_.write("pocket.ngc",
                 "G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\nG1 X10 Y10\nG1 X0 Y10\n"
                 "G1 X0 Y0\nG40 G1 X-5 Y-5\nG0 Z5\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const json whole = wait_until([](const json& s) { return s["exec"] == "idle"; });
  ASSERT_EQ(whole["program"]["result"], "done") << whole.dump();
  const json from = whole["position"]["commanded"];
  result_of(call("program.run", {{"from_line", 6}}));
  bool over = false;
  json s;
  for (;;) {
    s = status();
    const double x = s["position"]["commanded"]["x"], y = s["position"]["commanded"]["y"],
                 z = s["position"]["commanded"]["z"];
    const bool at_from =
        std::hypot(x - from["x"].get<double>(), y - from["y"].get<double>()) < 1e-6;
    const bool at_start = std::hypot(x - 9, y - 9) < 1e-6;
    if (at_start) over = true;
    if (!over && !at_from) {
      EXPECT_NEAR(z, 50.0, 1e-6) << "X" << x << " Y" << y;
    }
    // Cutting (below Z0) only on lines 6 and on: Y9 from X9 back, X1, and the way out.
    if (z < 0) {
      EXPECT_TRUE(over) << "X" << x << " Y" << y << " Z" << z;
      // Line 5 runs on X9 from Y1 to Y9 (corners blend within the path tolerance).
      EXPECT_FALSE(x > 8.5 && y < 8.5) << "line 5 cut again at X" << x << " Y" << y;
    }
    if (s["exec"] == "idle") break;
  }
  EXPECT_TRUE(over);
  EXPECT_EQ(end_state(s), end_state(whole)) << s.dump();
}

}  // namespace
}  // namespace cncd::test
