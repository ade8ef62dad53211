// Edge-case programs through the three ways a program is judged: cncd-check (the real binary),
// program.open and program.run on the real daemon. Each gives the same verdict and, for a
// program in error, the same line: arcs with an end radius off within LinuxCNC's tolerance
// (run as spirals) and beyond it, full circles, helices, zero-length moves, soft limits
// touched exactly and passed by a little, by a line or by an arc's bulge.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

struct EdgeCase {
  const char* name;
  std::string text;
  int error_line;  // 0: the program is good and runs to its end
  // Judged by the interpreter alone, as LinuxCNC's rs274 judges it (no soft limits there).
  bool interpreter_verdict;
};

// The sim machine's limits: X -10..300, Y -10..200, Z -100..50 (machine = program
// coordinates: G54 and G92 are zero in the example's parameter file).
const std::string kHead = "G21 G90 G17 G94\n";

// A full circle of radius 10 about X290.0002 Y100 bulges 0.2 um past X's MAX_LIMIT at angle
// 0; it starts half a step of a 256-step sampling of the circle away from there.
std::string bulging_circle() {
  const char* at = "[141.328125]";
  char text[400];
  std::snprintf(text, sizeof text,
                "#1=%s\nG0 X[290.0002+10*COS[#1]] Y[100+10*SIN[#1]] Z0\n"
                "G2 X[290.0002+10*COS[#1]] Y[100+10*SIN[#1]] I[-10*COS[#1]] J[-10*SIN[#1]] "
                "F3000\nM2\n",
                at);
  return kHead + text;
}

std::vector<EdgeCase> edge_cases() {
  return {
      {"spiral_within_tolerance", kHead + "G0 X0 Y0 Z0\nG2 X10 Y0 I5.005 J0 F600\nM2\n", 0, true},
      {"spiral_at_tolerance", kHead + "G0 X0 Y0 Z0\nG2 X10 Y0 I5.014 J0 F3000\nM2\n", 0, true},
      {"radius_beyond_tolerance", kHead + "G0 X0 Y0 Z0\nG1 Z-1 F600\nG2 X10 Y0 I5.015 J0\nM2\n", 4,
       true},
      {"zero_radius_arc", kHead + "G0 X5 Y5 Z0\nG2 X5 Y5 I0 J0 F600\nM2\n", 3, true},
      {"full_circles", kHead + "G0 X20 Y20 Z0\nG2 X20 Y20 I5 J0 F3000\nG3 X20 Y20 I0 J5\nM2\n", 0,
       true},
      {"helices",
       kHead + "G0 X20 Y20 Z0\nG3 X20 Y20 Z-5 I5 J0 P2 F3000\nG18 G2 X20 Z-5 I0 K2\n"
               "G19 G2 Y20 Z-5 J0 K2\nM2\n",
       0, true},
      {"zero_length_moves", kHead + "G0 X5 Y5 Z0\nG0 X5 Y5\nG1 X5 Y5 F600\nG1 X5\nG4 P0\nM2\n", 0,
       true},
      {"limits_touched_by_lines", kHead + "G0 X300 Y200 Z50\nG1 X-10 Y-10 F6000\nG0 Z0\nM2\n", 0,
       false},
      {"limits_touched_by_arcs",
       kHead + "G0 X280 Y100 Z0\nG2 X280 Y100 I10 J0 F6000\nG0 X100 Y10\nG3 X100 Y10 I0 J-10\nM2\n",
       0, false},
      {"line_just_beyond_a_limit", kHead + "G0 X10 Y10 Z0\nG0 X300.001\nM2\n", 3, false},
      // 11.81102363 in is 300.0000002 mm: an inch program's rounding past a limit.
      {"inch_line_beyond_a_limit_by_rounding",
       "G20 G90 G17 G94\nG0 X1 Y1 Z0\nG0 X11.81102363\nM2\n", 3, false},
      {"arc_bulging_just_beyond_a_limit", bulging_circle(), 4, false},
  };
}

class PipelineAgreementTest : public MachineTest {
 protected:
  // "" when cncd-check passes the program, else the first "FILE:LINE:" it reports.
  std::string check(const std::filesystem::path& program) {
    const auto r = run_command({CNCD_CHECK_BINARY, "--ini", ini_.string(), program.string()});
    if (r.exit_status == 0) return "";
    EXPECT_EQ(r.exit_status, 1) << r.err;
    return location(r.err);
  }

  // "" when program.open takes the program, else the line its error names.
  std::string open(const std::filesystem::path& program) {
    const json opened = call("program.open", {{"path", program.string()}});
    if (opened.contains("result")) return "";
    return location(opened["error"].value("message", ""));
  }

  // Runs `text` as `program` (opened while it held a harmless program when program.open
  // refuses it, as a file changed after it was opened); "" when it ran to its end.
  std::string run(const std::filesystem::path& program, const std::string& text) {
    dir_.write(program.filename().string(), "G21 G90\nG0 X1\nM2\n");
    result_of(call("program.open", {{"path", program.string()}}));
    dir_.write(program.filename().string(), text);
    const json ran = call("program.run");
    if (ran.contains("error")) return location(ran["error"].value("message", ""));
    const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
    if (s["program"]["result"] == "done") return "";
    EXPECT_EQ(s["program"]["result"], "error") << s.dump();
    return location(s["program"].value("error", ""));
  }

  // Each case gives the same verdict and line through cncd-check, program.open and
  // program.run.
  void expect_same_verdicts(const std::vector<EdgeCase>& cases) {
    for (const EdgeCase& c : cases) {
      SCOPED_TRACE(c.name);
      const auto program = dir_.write(std::string(c.name) + ".ngc", c.text);
      const std::string expected =
          c.error_line == 0 ? "" : program.string() + ":" + std::to_string(c.error_line) + ":";
      EXPECT_EQ(check(program), expected) << "cncd-check";
      EXPECT_EQ(open(program), expected) << "program.open";
      EXPECT_EQ(run(program, c.text), expected) << "program.run";
    }
  }

  // "FILE:LINE:" at the start of the first line of `text` that has one.
  static std::string location(const std::string& text) {
    const auto colon = text.find(".ngc:");
    if (colon == std::string::npos) return "?" + text;
    const auto end = text.find(':', colon + 5);
    const auto start = text.rfind('\n', colon);
    return text.substr(start == std::string::npos ? 0 : start + 1,
                       end == std::string::npos ? std::string::npos : end + 1 - (start + 1));
  }
};

TEST_F(PipelineAgreementTest, EveryPathGivesTheSameVerdictAtTheSameLine) {
  ready_machine();
  expect_same_verdicts(edge_cases());
}

// The trunnion example (sim_xyzac_trt.ini) under TCP: the tool tip stays within the axes'
// limits, but the table's turn carries the X joint past its own (the tip at X 180 Y 90 is
// 201.2 mm from the C axis, beyond X 200 between C -20 and C -33); the ends of the move are
// within them. Refused at that line three ways; a program that keeps its joints within
// their limits runs, and so does M428 with a rotary off 0. A rigid tap with the table tilted
// runs; a thread that turns A, and a probing move, are refused at their line. The G43 length
// in force is the tool's under TCP, for the joint limits too, and it changes only level.
const std::string kTrunnionHead = "G21 G90 G94\n";
const std::string kTilt = "G0 X0 Y-50 Z0 A0 C0\nM428\nG1 A-90 F600\nG0 A0\nM429\nM2\n";

class TrunnionAgreementTest : public PipelineAgreementTest {
 protected:
  std::string example() const override { return "sim_xyzac_trt"; }
};

TEST_F(TrunnionAgreementTest, AJointSwungPastItsLimitIsRefusedAtItsLine) {
  ready_machine();
  const std::string head = "G21 G90 G94\nG0 X0 Y0 Z0 A0 C0\nM428\n";
  const std::vector<EdgeCase> cases = {
      {"swing_past_joint_x", head + "G0 X180 Y90\nG1 C-50 F600\nG0 X0 Y0 C0\nM429\nM2\n", 5, false},
      {"swing_within_joints", head + "G0 X150 Y90\nG1 C-50 F600\nG0 X0 Y0 C0\nM429\nM2\n", 0,
       false},
      {"switch_off_zero", "G21 G90\nG0 X0 Y0 Z0 A-10 C0\nM428\nG1 X1 F600\nM429\nM2\n", 0, false},
      {"tap_tilted", head + "G0 A30\nG0 X5 Y5 Z5\nS600 M3\nG33.1 Z-5 K1.25\nG0 A0\nM429\nM2\n", 0,
       false},
      {"thread_turning_a", head + "G0 X5 Y5 Z5\nS600 M3\nG33 Z-5 A20 K1.25\nM429\nM2\n", 6, false},
      {"probe_under_tcp", head + "G0 X5 Y5 Z5\nG38.2 Z-5 F100\nM429\nM2\n", 5, false},
      // The tip at Y -50 tilted to A -90 takes the Z joint to 80 + the tool's length: past its
      // 120 with a 50 mm tool, within it with none.
      {"tool_length_past_joint_z", kTrunnionHead + "G43.1 Z50\n" + kTilt, 5, false},
      {"no_tool_length_within_joint_z", kTrunnionHead + "G49\n" + kTilt, 0, false},
      // A length change tilted would make the joints jump; level, it moves none.
      {"tool_length_change_tilted",
       kTrunnionHead + "G43.1 Z50\nG0 X0 Y0 Z0 A0 C0\nM428\nG1 A-30 F600\nG43.1 Z30\nG1 X5\nM2\n",
       6, false},
      {"tool_length_change_level",
       kTrunnionHead + "G43.1 Z30\nG0 X0 Y0 Z0 A0 C0\nM428\nG1 C90 F1800\nG43.1 Z50\nG1 A-30\n"
                       "G0 A0 C0\nM429\nM2\n",
       0, false},
  };
  expect_same_verdicts(cases);
}

// The interpreter's part of the verdicts is LinuxCNC's: rs274 accepts the same programs and
// stops at the same block.
TEST(PipelineAgreementOracle, Rs274GivesTheInterpreterVerdicts) {
  if (!std::filesystem::exists("/usr/bin/rs274")) GTEST_SKIP() << "LinuxCNC's rs274 is absent";
  TempDir dir;
  for (const EdgeCase& c : edge_cases()) {
    if (!c.interpreter_verdict) continue;
    SCOPED_TRACE(c.name);
    const auto program = dir.write(std::string(c.name) + ".ngc", c.text);
    const auto r = run_command({"/usr/bin/rs274", "-g", program.string()});
    EXPECT_EQ(r.exit_status, c.error_line == 0 ? 0 : 1) << r.out << r.err;
    if (c.error_line == 0) continue;
    // rs274 prints the block it stopped at after the error message.
    std::string block;
    std::size_t from = 0;
    for (int line = 1; line <= c.error_line; ++line) {
      const auto to = c.text.find('\n', from);
      block = c.text.substr(from, to - from);
      from = to + 1;
    }
    EXPECT_NE((r.out + r.err).find(block), std::string::npos) << r.out << r.err;
  }
}

}  // namespace
}  // namespace cncd::test
