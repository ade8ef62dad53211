// Run from a line on the real daemon: a 3D finishing program run from line 200 ends as the
// whole program does, with the spindle and coolant on before the line's moves, and the way to
// the line's start rises before it moves over.
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

}  // namespace
}  // namespace cncd::test
