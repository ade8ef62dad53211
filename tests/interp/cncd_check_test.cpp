// cncd-check and the program check behind it: summaries, soft limits in machine coordinates
// (arcs over their whole sweep), exit statuses, and the parameter file left alone.
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "cncd/pipeline/plan_sim.hpp"
#include "cncd/pipeline/program_check.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class CncdCheckTest : public ::testing::Test {
 protected:
  void SetUp() override { ini_ = copy_example_machine(dir_.path()); }

  CommandResult check(const std::string& program, std::vector<std::string> args = {}) {
    const auto path = dir_.write("prog.ngc", program);
    std::vector<std::string> argv{CNCD_CHECK_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.push_back(path.string());
    return run_command(argv);
  }
  CommandResult check_ini(const std::string& program) {
    return check(program, {"--ini", ini_.string()});
  }

  TempDir dir_;
  std::filesystem::path ini_;
};

TEST_F(CncdCheckTest, GoodProgramPrintsASummaryAndExitsZero) {
  const auto r = check_ini(
      "G21 G90 T2 M6\nG0 X1 Y2 Z3\nG1 X11 F100\nG2 X21 Y2 I5 J0\nG4 P1\n"
      "G99 G81 X4 Y5 Z1.5 R2.8 F100\nG80\nM2\n");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("moves: 7 (4 rapid, 2 feed, 1 arc), 1 dwell,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  X 1.0000 .. 21.0000\n"), std::string::npos) << r.out;
  // Clockwise from X11 to X21 around X16 Y2 the arc goes over the top, to Y7.
  EXPECT_NE(r.out.find("  Y 2.0000 .. 7.0000\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  Z 1.5000 .. 3.0000\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tools: T2\n"), std::string::npos) << r.out;
  // 10 straight + a half circle of radius 5 + the drill's 1.3 feed down.
  EXPECT_NE(r.out.find("feed path: 27.0080 mm\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("soft limits: every move within them"), std::string::npos) << r.out;
}

TEST_F(CncdCheckTest, ACompensatedProgramIsCheckedAndPlannedOnItsOffsetPath) {
  // A 4 mm tool left of three sides of a pocket: the corners trimmed 2 mm inside; the feeds
  // are sqrt(8^2 + 2^2) (the entry), 6 and 8 mm long.
  const std::string program =
      "G21 G90\nG0 X10 Y10 Z5\nF600\nG41.1 D4\nG1 X20 Y10\nG1 X20 Y20\nG1 X10 Y20\nG40\n"
      "G0 X5 Y5\nM2\n";
  const auto summary = check_ini(program);
  EXPECT_EQ(summary.exit_status, 0) << summary.err;
  EXPECT_NE(summary.out.find("  X 5.0000 .. 18.0000\n"), std::string::npos) << summary.out;
  EXPECT_NE(summary.out.find("  Y 5.0000 .. 18.0000\n"), std::string::npos) << summary.out;
  EXPECT_NE(summary.out.find("feed path: 22.2462 mm\n"), std::string::npos) << summary.out;
  const auto plan = check(program, {"--plan", "--ini", ini_.string()});
  EXPECT_EQ(plan.exit_status, 0) << plan.err;
  EXPECT_NE(plan.out.find("cycle time: "), std::string::npos) << plan.out;
  const auto canon = check(program, {"--canon"});
  EXPECT_EQ(canon.exit_status, 0) << canon.err;
  EXPECT_NE(canon.out.find("STRAIGHT_FEED(18.0000, 12.0000, 5.0000"), std::string::npos)
      << canon.out;
  EXPECT_NE(canon.out.find("STRAIGHT_FEED(10.0000, 18.0000, 5.0000"), std::string::npos)
      << canon.out;
}

TEST_F(CncdCheckTest, WithoutAnIniTheLimitsAreNotCheckedAndTheSummarySaysSo) {
  const auto r = check("G0 X5000\nM2\n");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("soft limits: not checked (no --ini"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  X 5000.0000 .. 5000.0000\n"), std::string::npos) << r.out;
}

TEST_F(CncdCheckTest, MovesBeyondTheSoftLimitsNameTheLineTheAxisAndTheLimit) {
  const auto r = check_ini("G21 G90\nG0 X10 Y10\nG0 X350\nG1 Z-120 F50\nM2\n");
  EXPECT_EQ(r.exit_status, 1);
  const std::string file = (dir_.path() / "prog.ngc").string();
  EXPECT_NE(r.err.find(file + ":3: rapid move: X 350.0000 is above [AXIS_X] MAX_LIMIT 300.0000"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(file + ":4: feed move: Z -120.0000 is below [AXIS_Z] MIN_LIMIT -100.0000"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("soft limits: 2 violations"), std::string::npos) << r.out;
}

TEST_F(CncdCheckTest, AbsurdTargetsAreNamedWithTheirValueNotHundredsOfDigits) {
  const auto r = check_ini("G0 X[10**300]\nM2\n");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find(":1: rapid move: X 1e+300 is above [AXIS_X] MAX_LIMIT 300.0000"),
            std::string::npos)
      << r.err;
}

TEST_F(CncdCheckTest, LimitsApplyInMachineCoordinatesAndUnits) {
  // G54 X250 puts program X60 at machine X310; 12 inches are 304.8 mm.
  auto r = check_ini("G10 L2 P1 X250\nG0 X40\nG0 X60\nM2\n");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find(":3: rapid move: X 310.0000 is above"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(":2:"), std::string::npos) << r.err;
  r = check_ini("G20 G0 X11.8\nG0 X12\nM2\n");
  EXPECT_NE(r.err.find(":2: rapid move: X 304.8000 is above"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(":1:"), std::string::npos) << r.err;
}

TEST_F(CncdCheckTest, TheParameterFileIsReadButNeverWritten) {
  const auto var = dir_.path() / "sim_mm.var";
  const std::string before = read_all(var);
  const auto r = check_ini("G10 L2 P1 X5 Y6\nG92 X1\nG0 X0\nM2\n");
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(read_all(var), before);
}

TEST_F(CncdCheckTest, AnInvalidIniListsEveryProblemAndExits78) {
  std::string text = read_all(ini_);
  const auto replace = [&text](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  };
  replace("MAX_LIMIT = 300", "MAX_LIMIT = far");
  replace("LINEAR_UNITS = mm", "LINEAR_UNITS = furlong");
  const auto bad = dir_.write("bad.ini", text);
  const auto r = check("G0 X1\nM2\n", {"--ini", bad.string()});
  EXPECT_EQ(r.exit_status, 78);
  EXPECT_NE(r.err.find("[AXIS_X] MAX_LIMIT"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[TRAJ] LINEAR_UNITS"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("problems in " + bad.string()), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(CncdCheckTest, MissingProgramBadUsageAndInterpreterErrors) {
  auto r = run_command({CNCD_CHECK_BINARY, "--ini", ini_.string(), "/nonexistent/part.ngc"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("/nonexistent/part.ngc"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(run_command({CNCD_CHECK_BINARY}).exit_status, 2);
  EXPECT_EQ(run_command({CNCD_CHECK_BINARY, "--bogus", "x.ngc"}).exit_status, 2);
  EXPECT_EQ(run_command({CNCD_CHECK_BINARY, "--ini"}).exit_status, 2);
  r = check_ini("G0 X1\nG82 X2 Y2 Z-1 R1 F10\nM2\n");
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("prog.ngc:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Dwell time p word missing with g82"), std::string::npos) << r.err;
}

// A user M code needs its executable in [RS274NGC] USER_M_PATH (or the program directory); one
// found nowhere stops the check at its line, as it would stop program.open and the run.
TEST_F(CncdCheckTest, UserMCodesAreLookedUpInUserMPath) {
  std::string text = read_all(ini_);
  const auto at = text.find("[RS274NGC]\n");
  ASSERT_NE(at, std::string::npos);
  text.insert(at + 11, "USER_M_PATH = um\n");
  const auto ini = dir_.write("user_m.ini", text);
  std::filesystem::create_directories(dir_.path() / "um");
  const auto m101 = dir_.write("um/M101", "#!/bin/sh\nexit 0\n");
  std::filesystem::permissions(m101, std::filesystem::perms::owner_all);
  auto r = check("G0 X1\nM101 P2 Q3\nM2\n", {"--ini", ini.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  r = check("G0 X1\nM101 P2\nM62 P1 M102\nM2\n", {"--ini", ini.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("prog.ngc:3:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Unknown m code used: M102"), std::string::npos) << r.err;
  r = check("G0 X1\nM101\nM2\n", {"--ini", ini_.string()});  // no USER_M_PATH
  EXPECT_NE(r.err.find("prog.ngc:2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Unknown m code used: M101"), std::string::npos) << r.err;
}

TEST_F(CncdCheckTest, AProgramThatNeverEndsIsStoppedWithAClearMessage) {
  const auto r = check("o1 while [1]\nG0 X1\nG0 X2\no1 endwhile\nM2\n", {"--max-seconds", "0.2"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("check stopped after 0.2000 s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the program runs too long to check"), std::string::npos) << r.err;
}

pipeline::CheckReport check_text(const TempDir& dir, const config::MachineConfig& machine,
                                 const std::string& program) {
  pipeline::CheckOptions options;
  options.interp = pipeline::interpreter_options(machine);
  options.machine = &machine;
  return pipeline::check_program(dir.write("arc.ngc", program), options);
}

TEST_F(CncdCheckTest, ArcsAreCheckedOverTheirWholeSweep) {
  const auto loaded = config::load_machine_config(ini_);
  ASSERT_TRUE(loaded.ok());
  const auto& machine = *loaded.config;
  // Both ends at Y160, within Y 200; clockwise over the top it reaches Y210.
  auto report = check_text(dir_, machine, "G0 X100 Y160\nG2 X200 Y160 I50 J0 F100\nM2\n");
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_EQ(report.problems[0].line, 2);
  EXPECT_NE(report.problems[0].message.find("arc: Y 210.0000 is above [AXIS_Y] MAX_LIMIT"),
            std::string::npos)
      << report.problems[0].message;
  // Counterclockwise it passes underneath, at Y110.
  report = check_text(dir_, machine, "G0 X100 Y160\nG3 X200 Y160 I50 J0 F100\nM2\n");
  EXPECT_TRUE(report.ok()) << report.problems.size();
  EXPECT_DOUBLE_EQ(report.min[1], 110.0);
  // XZ plane: seen from +Y, Z points right and X up; clockwise from below the centre goes
  // towards -Z and reaches Z-105 past MIN_LIMIT -100.
  report = check_text(dir_, machine, "G18 G0 X100 Z-90\nG2 X130 Z-90 I15 K0 F100\nM2\n");
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_NE(report.problems[0].message.find("Z -105.0000 is below [AXIS_Z] MIN_LIMIT"),
            std::string::npos)
      << report.problems[0].message;
  report = check_text(dir_, machine, "G18 G0 X100 Z-90\nG3 X130 Z-90 I15 K0 F100\nM2\n");
  EXPECT_TRUE(report.ok());
  EXPECT_DOUBLE_EQ(report.max[2], -75.0);
  // A full circle with extra turns (P3) reaches every side once, reported once per side.
  report = check_text(dir_, machine, "G0 X5 Y100\nG2 X5 Y100 I10 J0 P3 F100\nM2\n");
  EXPECT_EQ(report.limit_violations, 0u);
  EXPECT_DOUBLE_EQ(report.min[0], 5.0);
  EXPECT_DOUBLE_EQ(report.max[0], 25.0);
  report = check_text(dir_, machine, "G0 X-5 Y100\nG2 X-5 Y100 I10 J0 P3 F100\nM2\n");
  EXPECT_EQ(report.limit_violations, 0u);
  report = check_text(dir_, machine, "G0 X-5 Y195\nG2 X-5 Y195 I10 J0 P3 F100\nM2\n");
  ASSERT_EQ(report.limit_violations, 1u);
  EXPECT_NE(report.problems[0].message.find("Y 205.0000 is above"), std::string::npos);
  // A rotated coordinate system (G10 L2 R90) turns the arc's bulge from +Y to -X.
  report =
      check_text(dir_, machine, "G10 L2 P1 X0 Y100 R90\nG0 X0 Y0\nG2 X0 Y-20 I0 J-10 F100\nM2\n");
  ASSERT_EQ(report.limit_violations, 0u);
  EXPECT_NEAR(report.min[0], -0.0, 1e-9);
  EXPECT_NEAR(report.max[0], 20.0, 1e-9);
}

TEST_F(CncdCheckTest, AnArcIsJudgedOnThePlannersSegment) {
  const auto loaded = config::load_machine_config(ini_);
  ASSERT_TRUE(loaded.ok());
  const auto& machine = *loaded.config;
  // A spiral of three turns (the end 0.002 mm off the start's circle) reaches farthest on its
  // last turn: that is the figure reported, once per side.
  auto report = check_text(dir_, machine, "G0 X-5 Y195\nG2 X-5.002 Y195 I10 J0 P3 F100\nM2\n");
  ASSERT_EQ(report.limit_violations, 1u);
  EXPECT_NE(report.problems[0].message.find("arc: Y 205.00"), std::string::npos)
      << report.problems[0].message;
  // G10 L2 R on the system in use leaves the machine where it is, while the interpreter's
  // current point (the arc's start as its centre words are measured from) moves otherwise: in
  // machine coordinates the first arc starts on a circle about 1 mm from the one it ends on.
  // The machine would refuse it at its line; the check says so there too.
  report = check_text(dir_, machine,
                      "G0 X8.040\nG92 X3.232\nG0 X1.755 Y-1.348\n"
                      "G10 L2 P1 X4.525 Y4.647 R-22.5\n"
                      "G3 I-1.505 J1.653 F100\nG3 I1.920 J-1.786\nM2\n");
  ASSERT_EQ(report.problems.size(), 1u);
  EXPECT_EQ(report.problems[0].line, 5);
  EXPECT_NE(report.problems[0].message.find("arc: arc radius differs between start and end"),
            std::string::npos)
      << report.problems[0].message;
  pipeline::PlanSimOptions sim;
  sim.interp = pipeline::interpreter_options(machine);
  const auto plan = pipeline::simulate_plan(machine, dir_.path() / "arc.ngc", sim);
  ASSERT_TRUE(plan.error.has_value());
  EXPECT_EQ(plan.error->line, 5);
}

// --from-line prints what the lines before leave in force and what is done before the line,
// in order: the tool, the spindle and coolant, Z up, over the start, Z down at the feed.
TEST_F(CncdCheckTest, FromLinePrintsTheRebuiltStateAndTheWayToTheLine) {
  const std::string program =
      "G21 G90\nT1 M6\nS8000 M3\nM8\nG0 X30 Y20\nG1 Z-5 F1500\nG1 X40\nG1 Y30\nM2\n";
  const auto r = check(program, {"--ini", ini_.string(), "--from-line", "8"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  const std::vector<std::string> expected{
      "from line 8:\n",
      "  modal: G1 G17 G40 G21 G90 G94 G54 G49 G99 G64 G97 G91.1 G8 M3 M8 M48 M53\n",
      "  F1500.0000 S8000.0000 T1\n",
      "    wait for the tool change\n",
      "    spindle M3 8000.0000 rpm\n",
      "    coolant flood\n",
      "    wait for the spindle at speed\n",
      "    rapid to X0.0000 Y0.0000 Z50.0000\n",
      "    rapid to X40.0000 Y20.0000 Z50.0000\n",
      "    feed to X40.0000 Y20.0000 Z-5.0000 at 1500.0000 mm/min\n"};
  std::size_t at = 0;
  for (const auto& line : expected) {
    const auto found = r.out.find(line, at);
    ASSERT_NE(found, std::string::npos) << line << " in order in\n" << r.out;
    at = found + line.size();
  }
  // Only the moves from line 8 on are checked: X stays at 40.
  EXPECT_NE(r.out.find("  X 40.0000 .. 40.0000\n"), std::string::npos) << r.out;

  const auto past = check(program, {"--ini", ini_.string(), "--from-line", "12"});
  EXPECT_EQ(past.exit_status, 1);
  EXPECT_NE(past.err.find("prog.ngc:9: the program ends at line 9, before line 12"),
            std::string::npos)
      << past.err;
  EXPECT_EQ(check(program, {"--from-line", "0"}).exit_status, 2);
  EXPECT_EQ(check(program, {"--canon", "--from-line", "3"}).exit_status, 2);
}

// Under G41/G42 the move a line starts from is held back until the next block: the run reads
// on until the line's own move is out, and starts where the compensated path reaches the line,
// also after an arc, from a line without motion, and from one the program ends after. From the
// G40 line it starts where the compensated path left off and cuts no line before it again.
TEST_F(CncdCheckTest, FromALineUnderCutterCompensationStartsAtTheCompensatedPoint) {
  const std::string program =
      "G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\nG1 X10 Y10\nG1 X0 Y10\n"
      "G1 X0 Y0\nG40 G1 X-5 Y-5\nG0 Z5\nM2\n";
  const auto inside = check(program, {"--ini", ini_.string(), "--from-line", "6"});
  EXPECT_EQ(inside.exit_status, 0) << inside.err;
  // Line 5 (on X9, the tool's radius inside) ends at the corner X9 Y9; line 5 is not cut
  // again: the path checked stays at Y9 and below X9 from there.
  EXPECT_NE(inside.out.find("    rapid to X9.0000 Y9.0000 Z50.0000\n"
                            "    feed to X9.0000 Y9.0000 Z-1.0000 at 600.0000 mm/min\n"),
            std::string::npos)
      << inside.out;
  EXPECT_NE(inside.out.find("  X -5.0000 .. 9.0000\n  Y -5.0000 .. 9.0000\n"), std::string::npos)
      << inside.out;
  EXPECT_NE(inside.out.find("  modal: G1 G17 G41"), std::string::npos) << inside.out;
  // An arc before the line: its compensated end (radius 5 - 1 about X10 Y5) is the start.
  const auto arc = check(
      "G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\nG3 X10 Y10 R5\nG1 X0 Y10\n"
      "G40 G1 X-5 Y-5\nM2\n",
      {"--ini", ini_.string(), "--from-line", "6"});
  EXPECT_EQ(arc.exit_status, 0) << arc.err;
  EXPECT_NE(arc.out.find("    rapid to X10.0000 Y9.0000 Z50.0000\n"), std::string::npos) << arc.out;
  // A line without motion: the next move starts where line 5 ended.
  const auto message = check(
      "G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\nG1 X10 Y10\n(MSG, here)\n"
      "G1 X0 Y10\nG40 G1 X-5 Y-5\nM2\n",
      {"--ini", ini_.string(), "--from-line", "6"});
  EXPECT_EQ(message.exit_status, 0) << message.err;
  EXPECT_NE(message.out.find("    rapid to X9.0000 Y9.0000 Z50.0000\n"), std::string::npos)
      << message.out;
  // The program ends (M2) right after the line, compensation still on: down at the F in force.
  const auto ends =
      check("G21 G90 F600\nG0 X0 Y0 Z5\nG1 Z-1\nG41.1 D2 G1 X10 Y0\nG1 X10 Y10\nG1 X0 Y10\nM2\n",
            {"--ini", ini_.string(), "--from-line", "6"});
  EXPECT_EQ(ends.exit_status, 0) << ends.err;
  EXPECT_NE(ends.out.find("    feed to X9.0000 Y9.0000 Z-1.0000 at 600.0000 mm/min\n"),
            std::string::npos)
      << ends.out;
  const auto exit_line = check(program, {"--ini", ini_.string(), "--from-line", "8"});
  EXPECT_EQ(exit_line.exit_status, 0) << exit_line.err;
  // Line 7's compensated move ends at X1 Y0 (the tool's radius inside the corner): over there,
  // then down; only line 8's exit move is checked (line 7, up from Y9, is not cut again).
  EXPECT_NE(exit_line.out.find("    rapid to X1.0000 Y0.0000 Z50.0000\n"), std::string::npos)
      << exit_line.out;
  EXPECT_NE(exit_line.out.find("  Y -5.0000 .. -5.0000\n"), std::string::npos) << exit_line.out;
}

// A line inside a subroutine's definition is passed without being run where the program first
// reaches it: refused. A call's line and a loop's first pass start where asked.
TEST_F(CncdCheckTest, FromALineInsideASubroutineDefinitionIsRefusedAndACallLineWorks) {
  const std::string program =
      "G21 G90 F1000\no100 sub\n  G1 X#1 Y5\n  G1 Z-1\n  G0 Z5\no100 endsub\nG0 Z5\n"
      "o100 call [10]\no100 call [20]\no101 repeat [3]\n  G91 G1 X1\n  G90\n"
      "o101 endrepeat\nM2\n";
  const auto inside = check(program, {"--ini", ini_.string(), "--from-line", "4"});
  EXPECT_EQ(inside.exit_status, 1);
  EXPECT_NE(inside.err.find("prog.ngc:4: line 4 is not run where the program first reaches it"),
            std::string::npos)
      << inside.err;
  const auto call = check(program, {"--ini", ini_.string(), "--from-line", "9"});
  EXPECT_EQ(call.exit_status, 0) << call.err;
  // The first call's moves are skipped: the way leads to where it left the tool.
  EXPECT_NE(call.out.find("    rapid to X10.0000 Y5.0000 Z50.0000\n"
                          "    feed to X10.0000 Y5.0000 Z5.0000 at 1000.0000 mm/min\n"),
            std::string::npos)
      << call.out;
  EXPECT_NE(call.out.find("  X 10.0000 .. 23.0000\n"), std::string::npos) << call.out;
  const auto loop = check(program, {"--ini", ini_.string(), "--from-line", "11"});
  EXPECT_EQ(loop.exit_status, 0) << loop.err;
  EXPECT_NE(loop.out.find("    rapid to X20.0000 Y5.0000 Z50.0000\n"), std::string::npos)
      << loop.out;
}

// The machine's INI is there for #<_ini[SECTION]KEY>, read only.
TEST_F(CncdCheckTest, AProgramReadsTheMachinesIniValues) {
  const auto r =
      check("G21\n(debug, z=#<_ini[axis_z]max_limit>)\nG0 Z#<_ini[AXIS_Z]MIN_LIMIT>\nM2\n",
            {"--ini", ini_.string(), "--canon"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("MESSAGE(\" z=50.000000\")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("STRAIGHT_TRAVERSE(0.0000, 0.0000, -100.0000"), std::string::npos) << r.out;
  const auto assigned = check("#<_ini[AXIS_Z]MAX_LIMIT> = 5\nM2\n", {"--ini", ini_.string()});
  EXPECT_EQ(assigned.exit_status, 1);
  EXPECT_NE(assigned.err.find("Cannot assign to read-only parameter #<_ini[axis_z]max_limit>"),
            std::string::npos)
      << assigned.err;
  // Without an INI there is no such parameter.
  EXPECT_NE(check("(debug, #<_ini[AXIS_Z]MAX_LIMIT>)\nG0 Z#<_ini[AXIS_Z]MAX_LIMIT>\nM2\n")
                .err.find("not defined"),
            std::string::npos);
}

}  // namespace
}  // namespace cncd::test
