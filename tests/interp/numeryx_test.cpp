// The Numeryx dialect against every statement of its application note (seed 002, An-101):
// cycle heights, Zi, the cycle's own variables and distance mode, G98/G99/G80, D, units, the
// plane, tapping, the syntax (bare g, '=' expressions, empty words, for/next, gil(), g10 polar)
// and the errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

class Recorder final : public CanonSink {
 public:
  void emit(const CanonCommand& command) override {
    if (std::holds_alternative<StraightTraverse>(command.op) ||
        std::holds_alternative<StraightFeed>(command.op) ||
        std::holds_alternative<Dwell>(command.op)) {
      moves.push_back(format_rs274(command, 3));
    }
    all.push_back(format_rs274(command));
    ops.push_back(command.op);
  }
  std::vector<std::string> moves;
  std::vector<std::string> all;
  std::vector<CanonOp> ops;
};

struct Outcome {
  Recorder recorder;
  std::optional<InterpError> error;
  Dialect dialect = Dialect::linuxcnc;
};

Outcome run(const std::string& program, InterpOptions options = {}) {
  Interpreter interp(std::move(options));
  Outcome result;
  result.error = interp.open_string(program, "nx.ngc");
  result.dialect = interp.dialect();
  if (!result.error) result.error = run_program(interp, result.recorder);
  return result;
}

std::vector<std::string> moves(const std::string& program, InterpOptions options = {}) {
  Outcome r = run("(dialect numeryx)\n" + program, std::move(options));
  EXPECT_FALSE(r.error) << (r.error ? r.error->to_string() : "");
  return r.recorder.moves;
}

std::string error_of(const std::string& program) {
  Outcome r = run("(dialect numeryx)\n" + program);
  return r.error ? r.error->to_string() : "no error";
}

// A hole: a feed straight down at one XY; its top is where the feed starts, its bottom the
// lowest Z reached there, and `retract` the Z the tool leaves the hole at.
struct Hole {
  double x = 0;
  double y = 0;
  double top = 0;
  double bottom = 0;
  double retract = 0;
};

std::vector<Hole> holes(const std::vector<CanonOp>& ops) {
  std::vector<Hole> out;
  Pose at{};
  bool in_hole = false;
  for (const auto& op : ops) {
    const Pose* end = nullptr;
    bool feed = false;
    if (const auto* t = std::get_if<StraightTraverse>(&op)) end = &t->end;
    if (const auto* f = std::get_if<StraightFeed>(&op)) {
      end = &f->end;
      feed = true;
    }
    if (end == nullptr) continue;
    const bool same_xy = (*end)[0] == at[0] && (*end)[1] == at[1];
    if (!same_xy) in_hole = false;
    if (feed && same_xy && (*end)[2] < at[2]) {
      if (!in_hole) out.push_back(Hole{at[0], at[1], at[2], (*end)[2], (*end)[2]});
      in_hole = true;
      out.back().bottom = std::min(out.back().bottom, (*end)[2]);
    }
    if (in_hole) out.back().retract = (*end)[2];
    at = *end;
  }
  return out;
}

std::vector<Hole> holes_of(const std::string& program, InterpOptions options = {}) {
  Outcome r = run("(dialect numeryx)\n" + program, std::move(options));
  EXPECT_FALSE(r.error) << (r.error ? r.error->to_string() : "");
  return holes(r.recorder.ops);
}

void expect_hole(const Hole& h, double x, double y, double top, double bottom, double retract) {
  EXPECT_NEAR(h.x, x, 1e-9);
  EXPECT_NEAR(h.y, y, 1e-9);
  EXPECT_NEAR(h.top, top, 1e-9);
  EXPECT_NEAR(h.bottom, bottom, 1e-9);
  EXPECT_NEAR(h.retract, retract, 1e-9);
}

// --- cycle heights ------------------------------------------------------------------------

TEST(Numeryx, OneBlockAndTwoBlockFormatsDrillTheSameHoles) {
  const auto one = moves(
      "n1 g x10 y20 z10 f100 g81 r-2 z-5 g91\n"
      "n2 x30\nn3 g80\nm30\n");
  const auto two = moves(
      "n1 g x10 y20 z10 f100\n"
      "n2 g81 r-2 z-5 g91\n"
      "n3 x30\nn4 g80\nm30\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(10.0000, 20.0000, 10.0000)",  // the positioning block: Zi = 10
      "STRAIGHT_TRAVERSE(10.0000, 20.0000, 9.0000)",   // rapid to R1 = (10 - 2) + 1
      "STRAIGHT_FEED(10.0000, 20.0000, 3.0000)",       // feed to R + Z = 8 - 5
      "STRAIGHT_TRAVERSE(10.0000, 20.0000, 10.0000)",  // G98: back to Zi
      "STRAIGHT_TRAVERSE(30.0000, 20.0000, 10.0000)",  // subsequent lines: a new position
      "STRAIGHT_TRAVERSE(30.0000, 20.0000, 9.0000)",  "STRAIGHT_FEED(30.0000, 20.0000, 3.0000)",
      "STRAIGHT_TRAVERSE(30.0000, 20.0000, 10.0000)",
  };
  EXPECT_EQ(one, expected);
  EXPECT_EQ(two, expected);
}

TEST(Numeryx, RIsWhereDrillingBeginsAndR1IsOneMillimetreAbove) {
  const auto h = holes_of("g x0 y0 z20 f100 g81 r5 z-5\ng80\nm30\n");
  ASSERT_EQ(h.size(), 1U);
  expect_hole(h[0], 0, 0, 6, -5, 20);
}

TEST(Numeryx, ClearanceIs004InchInAnInchProgram) {
  const auto h = holes_of("g20\ng x0 y0 z.5 f8 g81 r0 z-.3\ng80\nm30\n");
  ASSERT_EQ(h.size(), 1U);
  expect_hole(h[0], 0, 0, 0.04, -0.3, 0.5);
}

TEST(Numeryx, ClearanceComesFromTheMachineInItsUnits) {
  InterpOptions options;
  options.numeryx_clearance = 2.54;  // mm on a mm machine: 0.1 in in a G20 program
  auto h = holes_of("g x0 y0 z20 f100 g81 r5 z-5\ng80\nm30\n", options);
  ASSERT_EQ(h.size(), 1U);
  EXPECT_NEAR(h[0].top, 7.54, 1e-9);
  h = holes_of("g20\ng x0 y0 z1 f8 g81 r0 z-.3\ng80\nm30\n", options);
  ASSERT_EQ(h.size(), 1U);
  EXPECT_NEAR(h[0].top, 0.1, 1e-9);
}

// "Whenever Z is read from a positioning block current Z is saved into variable Zi."
TEST(Numeryx, EveryPositioningZBecomesTheInitialZ) {
  const auto h = holes_of(
      "g x0 y0 z10 f100\n"
      "g z25\n"       // no cycle yet: Zi = 25
      "g81 r2 z-3\n"  // drills at (0, 0) and retracts to 25
      "x10 z15\n"     // positioning Z under the cycle: Zi = 15
      "x20\n"         // back to 15
      "g80\nm30\n");
  ASSERT_EQ(h.size(), 3U);
  expect_hole(h[0], 0, 0, 3, -3, 25);
  expect_hole(h[1], 10, 0, 3, -3, 15);
  expect_hole(h[2], 20, 0, 3, -3, 15);
}

// "When R,Z,Q,D are entered after g81 in the same block they are redirected to internal
// variables and the corresponding NC addresses do not change."
TEST(Numeryx, CycleWordsDoNotMoveTheAxis) {
  const auto m = moves("g x0 y0 z10 f100 g81 r2 z-5\ng80\ng x7\nm30\n");
  ASSERT_FALSE(m.empty());
  // The block's Z after g81 is the bottom, not a position: the tool ends at Zi and the
  // next positioning stays there.
  EXPECT_EQ(m.front(), "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)");
  EXPECT_EQ(m.back(), "STRAIGHT_TRAVERSE(7.0000, 0.0000, 10.0000)");
  // Z before the cycle word positions (Zi), Z after it is the bottom.
  const auto h = holes_of("g x0 y0 z12 f100 g81 r2 z-5\ng80\nm30\n");
  ASSERT_EQ(h.size(), 1U);
  expect_hole(h[0], 0, 0, 3, -5, 12);
}

// "D is set to zero when a fresh cycle begins."
TEST(Numeryx, DIsADwellAtTheBottomResetByAFreshCycle) {
  const auto m = moves(
      "g x0 y0 z10 f100 g82 r0 z-5 d1.5\n"
      "g81 z-6\n"  // written again: D stays
      "x5\n"
      "g80\n"
      "g81 r0 z-5\n"  // fresh: D = 0
      "g80\nm30\n");
  int dwells = 0;
  for (const auto& line : m)
    if (line == "DWELL(1.5000)") ++dwells;
  EXPECT_EQ(dwells, 3);  // g82, the rewritten g81 and x5; none after the fresh g81
  EXPECT_EQ(std::count_if(m.begin(), m.end(),
                          [](const std::string& s) { return s.rfind("DWELL", 0) == 0; }),
            3);
}

// "A fresh g81 begins with g90 active. Also as long as g81 is active, g90/g91 do not affect the
// regular Absolute/Incremental for X and Y (until g80)."
TEST(Numeryx, TheCycleHasItsOwnDistanceMode) {
  const auto h = holes_of(
      "g x0 y0 z10 f100 g81 r-2 z-5\n"  // G90 R and Z: R1 = -1, bottom -5
      "g91 x20\n"                       // G91 for R and Z only: X stays absolute (20)
      "x30\n"
      "g80\n"
      "g x40\n"        // after g80 X is still absolute
      "g81 r-2 z-5\n"  // fresh: G90 again
      "g80\nm30\n");
  ASSERT_EQ(h.size(), 4U);
  expect_hole(h[0], 0, 0, -1, -5, 10);
  expect_hole(h[1], 20, 0, 9, 3, 10);  // R = Zi - 2 = 8, R1 = 9, bottom = 8 - 5
  expect_hole(h[2], 30, 0, 9, 3, 10);
  expect_hole(h[3], 40, 0, -1, -5, 10);
}

TEST(Numeryx, G91BeforeTheCycleWordIsTheXYDistanceMode) {
  const auto h = holes_of("g x5 y5 z10 f100\ng91 g x10 g81 r-2 z-5\ng80\nm30\n");
  ASSERT_EQ(h.size(), 1U);
  expect_hole(h[0], 15, 5, -1, -5, 10);
}

// "With g98 (default), the tool retracts to the initial Z. With g99, to the R1 plane.
// G98/G99 can be programmed any time, but g80 cancels g99."
TEST(Numeryx, G98RetractsToZiG99ToR1AndG80CancelsG99) {
  const auto h = holes_of(
      "g x0 y0 z10 f100 g81 r0 z-5\n"  // G98 by default
      "x5 g99\n"
      "x10\n"
      "g98 x15\n"
      "g99\n"
      "g80\n"
      "g x20 g81 r0 z-5\n"  // fresh after g80: G98 again
      "g80\nm30\n");
  ASSERT_EQ(h.size(), 5U);
  EXPECT_NEAR(h[0].retract, 10, 1e-9);
  EXPECT_NEAR(h[1].retract, 1, 1e-9);
  EXPECT_NEAR(h[2].retract, 1, 1e-9);
  EXPECT_NEAR(h[3].retract, 10, 1e-9);
  EXPECT_NEAR(h[4].retract, 10, 1e-9);
}

TEST(Numeryx, G99BeforeAFreshCycleHolds) {
  const auto h = holes_of("g99\ng x0 y0 z10 f100 g81 r0 z-5\nx5\ng80\nm30\n");
  ASSERT_EQ(h.size(), 2U);
  EXPECT_NEAR(h[0].retract, 1, 1e-9);
  EXPECT_NEAR(h[1].retract, 1, 1e-9);
}

// "To modify the drilling variables in the middle, e.g., the drilling depth, g81 must be
// written again, but this doesn't reset the defaults, as is the case with a fresh g81."
TEST(Numeryx, WritingTheCycleAgainChangesOnlyWhatItGives) {
  const auto h = holes_of(
      "g x0 y0 z10 f100 g81 r-2 z-5 g91 d0.5\n"
      "g81 z-8 x10\n"  // still G91 from Zi, R still -2, D still 0.5
      "g80\nm30\n");
  ASSERT_EQ(h.size(), 2U);
  expect_hole(h[0], 0, 0, 9, 3, 10);
  expect_hole(h[1], 10, 0, 9, 0, 10);
}

// "The drilling is always in the Z axis and the positioning in the X,Y axes. Plane select
// mode (g17 - g19) is ignored for drilling."
TEST(Numeryx, ThePlaneSelectIsIgnored) {
  for (const char* plane : {"g17", "g18", "g19"}) {
    SCOPED_TRACE(plane);
    const auto h = holes_of(std::string(plane) + "\ng x3 y4 z10 f100 g81 r0 z-5\nx6\ng80\nm30\n");
    ASSERT_EQ(h.size(), 2U);
    expect_hole(h[0], 3, 4, 1, -5, 10);
    expect_hole(h[1], 6, 4, 1, -5, 10);
  }
}

// "The drilling variables are saved in the unit they were given (inch-mm) therefore after
// they are defined scale is allowed but not inch/metric switching."
TEST(Numeryx, UnitsMayNotSwitchUnderACycle) {
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g81 r0 z-5\ng20 x1\ng80\nm30\n"),
            "nx.ngc:3:1: Cannot switch between inch and metric while a drilling cycle is "
            "active: its R, Z and Q keep the units they were given (g80 first)");
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g81 r0 z-5 g20\nm30\n"),
            "nx.ngc:2:29: Cannot switch between inch and metric while a drilling cycle is "
            "active: its R, Z and Q keep the units they were given (g80 first)");
  // The same units again, and a switch after g80, are fine; Zi follows the switch.
  const auto h = holes_of(
      "g x0 y0 z25.4 f100 g81 r0 z-5\ng21 x5\ng80\ng20\ng81 r0 z-.2\n"
      "g80\nm30\n");
  ASSERT_EQ(h.size(), 3U);
  expect_hole(h[2], 5 / 25.4, 0, 0.04, -0.2, 1.0);
}

// --- the cycles ---------------------------------------------------------------------------

TEST(Numeryx, PeckCyclesMeasureTheirPecksFromR) {
  const auto m = moves("g x0 y0 z10 f100 g83 r0 z-7 q3\ng80\nm30\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)", "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",
      "STRAIGHT_FEED(0.0000, 0.0000, -3.0000)",     "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, -2.7460)", "STRAIGHT_FEED(0.0000, 0.0000, -6.0000)",
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",  "STRAIGHT_TRAVERSE(0.0000, 0.0000, -5.7460)",
      "STRAIGHT_FEED(0.0000, 0.0000, -7.0000)",     "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)",
  };
  EXPECT_EQ(m, expected);
  const auto chip_break = moves("g x0 y0 z10 f100 g73 r0 z-4 q3\ng80\nm30\n");
  const std::vector<std::string> expected73{
      "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)", "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",
      "STRAIGHT_FEED(0.0000, 0.0000, -3.0000)",     "STRAIGHT_TRAVERSE(0.0000, 0.0000, -2.7460)",
      "STRAIGHT_FEED(0.0000, 0.0000, -4.0000)",     "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)",
  };
  EXPECT_EQ(chip_break, expected73);
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g83 r0 z-7\nm30\n"),
            "nx.ngc:2:18: g83 needs a positive Q, the depth of each peck (q after g83)");
}

TEST(Numeryx, BoringFeedsOutToR1AndG86StopsTheSpindle) {
  EXPECT_EQ(
      moves("g x0 y0 z10 f100 g85 r0 z-5\ng80\nm30\n"),
      (std::vector<std::string>{
          "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)", "STRAIGHT_TRAVERSE(0.0000, 0.0000, 1.0000)",
          "STRAIGHT_FEED(0.0000, 0.0000, -5.0000)", "STRAIGHT_FEED(0.0000, 0.0000, 1.0000)",
          "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000)"}));
  Outcome r = run("(dialect numeryx)\ns500 m3\ng x0 y0 z10 f100 g86 r0 z-5\ng80\nm30\n");
  ASSERT_FALSE(r.error) << r.error->to_string();
  const auto& all = r.recorder.all;
  const auto bottom = std::find(all.begin(), all.end(),
                                "STRAIGHT_FEED(0.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)");
  ASSERT_NE(bottom, all.end());
  EXPECT_EQ(*(bottom + 1), "STOP_SPINDLE_TURNING(0)");
  EXPECT_EQ(*(bottom + 2), "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)");
  EXPECT_EQ(*(bottom + 3), "START_SPINDLE_CLOCKWISE(0)");
}

// "G84 is used for flexible tapping and either g84 or g74 for rigid tapping": g84 is
// LinuxCNC's floating cycle from R1 unless the machine taps rigidly (rigid_tapping).
TEST(Numeryx, G84IsFlexibleTappingUnlessTheMachineTapsRigidly) {
  Outcome r = run("(dialect numeryx)\ns300 m3\ng x0 y0 z10 f375 g84 r0 z-8\ng80\nm30\n");
  ASSERT_FALSE(r.error) << r.error->to_string();
  const auto& all = r.recorder.all;
  const auto bottom = std::find(all.begin(), all.end(),
                                "STRAIGHT_FEED(0.0000, 0.0000, -8.0000, 0.0000, 0.0000, 0.0000)");
  ASSERT_NE(bottom, all.end());
  EXPECT_EQ(*(bottom + 1), "STOP_SPINDLE_TURNING(0)");
  EXPECT_EQ(*(bottom + 2), "START_SPINDLE_COUNTERCLOCKWISE(0)");
  EXPECT_EQ(*(bottom + 3), "STRAIGHT_FEED(0.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)");
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g84 r0 z-8\nm30\n"), "nx.ngc:2: Spindle not turning in G84");

  InterpOptions options;
  options.rigid_tapping = true;
  Outcome rigid =
      run("(dialect numeryx)\ns300 m3\ng x0 y0 z10 f1250 g84 r0 z-8\ng80\nm30\n", options);
  ASSERT_FALSE(rigid.error) << rigid.error->to_string();
  EXPECT_NE(std::find(rigid.recorder.all.begin(), rigid.recorder.all.end(),
                      "RIGID_TAP(0.0000, 0.0000, -8.0000)"),
            rigid.recorder.all.end());
}

// The lines of a program from its first START_SPEED_FEED_SYNC (or the spindle's start before
// it) up to g80 or m30, without the SET_ commands.
std::vector<std::string> tap_lines(const std::string& program) {
  Outcome r = run("(dialect numeryx)\n" + program);
  EXPECT_FALSE(r.error) << r.error->to_string();
  const auto& all = r.recorder.all;
  auto from = std::find_if(all.begin(), all.end(), [](const std::string& line) {
    return line.starts_with("START_SPEED_FEED_SYNC");
  });
  if (from != all.begin() && from != all.end() && (from - 1)->starts_with("START_SPINDLE")) --from;
  const auto to = std::find_if(from, all.end(), [](const std::string& line) {
    return line == "COMMENT(\"interpreter: retract mode set to old_z\")" ||
           line.starts_with("SET_G5X_OFFSET");  // m30
  });
  std::vector<std::string> lines(from, to);
  std::erase_if(lines, [](const std::string& line) { return line.starts_with("SET_"); });
  return lines;
}

// g74 is rigid tapping, right hand: no M3 needed (a spindle at rest turns for the hole and
// stops after it), F the pitch in thousandths of the program's unit as the note's table writes
// it (f1250 = 1.25 mm), from R1 down and back, then to Zi (g98).
TEST(Numeryx, G74IsRigidTappingWithThePitchInThousandths) {
  EXPECT_EQ(tap_lines("s500\ng x0 y0 z10 f1250 g74 r0 z-8\ng80\nm30\n"),
            (std::vector<std::string>{
                "START_SPINDLE_CLOCKWISE(0)",
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(0.0000, 0.0000, -8.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)",
                "STOP_SPINDLE_TURNING(0)",
            }));
  // Turning already (M3): it keeps turning. g99 comes back to R1 only.
  EXPECT_EQ(tap_lines("s500 m3\ng99\ng x0 y0 z10 f1250 g74 r0 z-8\nx5\ng80\nm30\n"),
            (std::vector<std::string>{
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(0.0000, 0.0000, -8.0000)",
                "STOP_SPEED_FEED_SYNCH()",
                "STRAIGHT_TRAVERSE(5.0000, 0.0000, 1.0000, 0.0000, 0.0000, 0.0000)",
                "START_SPEED_FEED_SYNC(1.250000,0)",
                "RIGID_TAP(5.0000, 0.0000, -8.0000)",
                "STOP_SPEED_FEED_SYNCH()",
            }));
  // The note's pitch table: inch f125 = 0.125 in, f=1000/13 = 13 TPI, f=1250/25.4 = 1.25 mm;
  // metric f=25400/13 = 13 TPI, f=125*25.4 = 0.125 in.
  const std::vector<std::pair<std::string, std::string>> table{
      {"g20\ns500\ng x0 y0 z1 f125 g74 r0 z-.5\n", "START_SPEED_FEED_SYNC(0.125000,0)"},
      {"g20\ns500\ng x0 y0 z1 f=1000/13 g74 r0 z-.5\n", "START_SPEED_FEED_SYNC(0.076923,0)"},
      {"g20\ns500\ng x0 y0 z1 f=1250/25.4 g74 r0 z-.5\n", "START_SPEED_FEED_SYNC(0.049213,0)"},
      {"s500\ng x0 y0 z10 f=25400/13 g74 r0 z-8\n", "START_SPEED_FEED_SYNC(1.953846,0)"},
      {"s500\ng x0 y0 z10 f=125*25.4 g74 r0 z-8\n", "START_SPEED_FEED_SYNC(3.175000,0)"},
  };
  for (const auto& [program, synch] : table) {
    const auto lines = tap_lines(program + "g80\nm30\n");
    ASSERT_GE(lines.size(), 2U) << program;
    EXPECT_EQ(lines[1], synch) << program;
  }
}

TEST(Numeryx, RigidTappingErrorsSayWhatIsWrong) {
  EXPECT_EQ(error_of("s500\ng x0 y0 z10 f1.25 g74 r0 z-8\nm30\n"),
            "nx.ngc:3:13: Tapping pitch F1.25 is 0.00125 mm per revolution: in the Numeryx "
            "dialect F gives the pitch in thousandths of a mm (f1250 = 1.25 mm)");
  EXPECT_EQ(error_of("g20\ns500\ng x0 y0 z1 f.125 g74 r0 z-.5\nm30\n"),
            "nx.ngc:4:12: Tapping pitch F0.125 is 0.000125 in per revolution: in the Numeryx "
            "dialect F gives the pitch in thousandths of an inch (f125 = 0.125 in)");
  EXPECT_EQ(error_of("g x0 y0 z10 f1250 g74 r0 z-8\nm30\n"),
            "nx.ngc:2: Cannot do rigid tapping with zero spindle speed in g74");
  EXPECT_EQ(error_of("s500 m4\ng x0 y0 z10 f1250 g74 r0 z-8\nm30\n"),
            "nx.ngc:3: Spindle turning counterclockwise in g74: Numeryx taps right-hand with g74 "
            "and g84");
}

// --- syntax -------------------------------------------------------------------------------

TEST(Numeryx, BareGIsARapidAndValuesMayBeExpressions) {
  const auto m = moves(
      "#2=4\n"
      "n10 g x=#2*2+1 y=1000/8 z=-(1+2)*-3\n"
      "N20 G1 X=-#2 F=25400/13\n"
      "m30\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(9.0000, 125.0000, 9.0000)",
      "STRAIGHT_FEED(-4.0000, 125.0000, 9.0000)",
  };
  EXPECT_EQ(m, expected);
  Outcome r = run("(dialect numeryx)\ng1 x1 f=25400/13\nm30\n");
  ASSERT_FALSE(r.error);
  EXPECT_NE(std::find(r.recorder.all.begin(), r.recorder.all.end(), "SET_FEED_RATE(1953.8462)"),
            r.recorder.all.end());
}

// An empty address word reads as 0: "r" is the R plane at Z0, "i j" a pole at the origin.
TEST(Numeryx, AnEmptyWordIsZero) {
  auto h = holes_of("g20\ng x1 y1 z.5 g81 r z-.3 f8\ng80\nm30\n");
  ASSERT_EQ(h.size(), 1U);
  expect_hole(h[0], 1, 1, 0.04, -0.3, 0.5);
  h = holes_of("g10 i j r4 p90 z.5 g81 r z-.3 f8\ng80\nm30\n");
  ASSERT_EQ(h.size(), 1U);
  EXPECT_NEAR(h[0].x, 0, 1e-12);
  EXPECT_NEAR(h[0].y, 4, 1e-12);
}

TEST(Numeryx, G10PositionsAroundItsPoleAndKeepsItsValues) {
  const auto m = moves("g10 i10 j5 r2 p0 z3\ng10 p90\ng10 i0 j0 r1 p180\nm30\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(12.0000, 5.0000, 3.0000)",
      "STRAIGHT_TRAVERSE(10.0000, 7.0000, 3.0000)",
      "STRAIGHT_TRAVERSE(-1.0000, 0.0000, 3.0000)",
  };
  EXPECT_EQ(m, expected);
  EXPECT_EQ(error_of("g10 x1 r2 p0\nm30\n"),
            "nx.ngc:2:5: Cannot use x with g10: the polar position (i, j, p, r) gives x and y");
}

// gil(x0,xn) in a loop 0 to 4 over 50 .. 150 gives 50, 75, 100, 125, 150.
TEST(Numeryx, GilGivesTheNotesValues) {
  const auto m = moves("for #1=0 to 4\ng x=gil(50,150)\nnext #1\nm30\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(50.0000, 0.0000, 0.0000)",  "STRAIGHT_TRAVERSE(75.0000, 0.0000, 0.0000)",
      "STRAIGHT_TRAVERSE(100.0000, 0.0000, 0.0000)", "STRAIGHT_TRAVERSE(125.0000, 0.0000, 0.0000)",
      "STRAIGHT_TRAVERSE(150.0000, 0.0000, 0.0000)",
  };
  EXPECT_EQ(m, expected);
}

TEST(Numeryx, LoopsNestStepAndRunNoPassWhenEmpty) {
  const auto nested = moves("for #1=1 to 2\nfor #2=0 to 1\ng x=#1 y=#2\nnext #2\nnext #1\nm30\n");
  const std::vector<std::string> expected{
      "STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.0000)",
      "STRAIGHT_TRAVERSE(1.0000, 1.0000, 0.0000)",
      "STRAIGHT_TRAVERSE(2.0000, 0.0000, 0.0000)",
      "STRAIGHT_TRAVERSE(2.0000, 1.0000, 0.0000)",
  };
  EXPECT_EQ(nested, expected);
  const auto stepped = moves("for #3=10 to 0 step -5\ng x=#3\nnext\nm30\n");
  EXPECT_EQ(stepped, (std::vector<std::string>{"STRAIGHT_TRAVERSE(10.0000, 0.0000, 0.0000)",
                                               "STRAIGHT_TRAVERSE(5.0000, 0.0000, 0.0000)",
                                               "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000)"}));
  const auto tenths = moves("for #1=0 to 1 step .25\ng x=#1\nnext #1\nm30\n");
  EXPECT_EQ(tenths.size(), 5U);
  // A loop that runs no pass skips its body (and loops inside it); its next line's other
  // words still run.
  const auto empty = moves("for #1=1 to 0\nfor #2=0 to 3\ng x9\nnext #2\nnext #1 g x4\nm30\n");
  EXPECT_EQ(empty, (std::vector<std::string>{"STRAIGHT_TRAVERSE(4.0000, 0.0000, 0.0000)"}));
}

// "next #1 g80": the words after next run once, when the loop is done.
TEST(Numeryx, TheRestOfTheNextLineRunsAfterTheLoop) {
  Outcome r =
      run("(dialect numeryx)\nfor #1=0 to 2\ng x=#1*10 y0 z5 g81 r0 z-2 f100\nnext #1 g80\n"
          "g x50\nm30\n");
  ASSERT_FALSE(r.error) << r.error->to_string();
  EXPECT_EQ(holes(r.recorder.ops).size(), 3U);
  EXPECT_EQ(r.recorder.moves.back(), "STRAIGHT_TRAVERSE(50.0000, 0.0000, 5.0000)");
}

TEST(Numeryx, LoopErrorsNameTheLine) {
  EXPECT_EQ(error_of("for #1=0 to 3\ng x1\nnext #2\nm30\n"),
            "nx.ngc:4:1: next #2 does not close the loop of for #1 (line 2)");
  EXPECT_EQ(error_of("next #1\nm30\n"), "nx.ngc:2:1: next without a for loop");
  EXPECT_EQ(error_of("g x=gil(0,1)\nm30\n"), "nx.ngc:2:5: gil() used outside a for loop");
  EXPECT_EQ(error_of("for #1=0 to 0\ng x=gil(0,1)\nnext\nm30\n"),
            "nx.ngc:3:5: gil() in a for loop whose end value is 0: it gives x0 + (xn - x0) x "
            "#n / end");
  EXPECT_EQ(error_of("for #1=0 7\nm30\n"),
            "nx.ngc:2:11: 'to' missing in the for loop (for #1=0 to 7)");
  EXPECT_EQ(error_of("for #1=0 to 3 step 0\nnext\nm30\n"),
            "nx.ngc:2:20: Step 0 in a for loop never ends");
  EXPECT_EQ(error_of("for #1=1 to 0\ng x1\nm30\n"), "nx.ngc:2: for loop without next");
  EXPECT_EQ(error_of("for #1=0 to 3 g x1\nnext\nm30\n"),
            "nx.ngc:2:1: Nothing but the loop may stand on a for line");
}

// --- the note's hole patterns -------------------------------------------------------------

TEST(Numeryx, EightHolesOnASlope) {
  const auto h = holes_of(
      "g20\nfor #1=0 to 7\ng x=gil(1,4.5) y=gil(1,2.75) z.5 g81 r z-.3 f8\nnext #1 g80\nm30\n");
  ASSERT_EQ(h.size(), 8U);
  for (std::size_t i = 0; i < h.size(); ++i) {
    SCOPED_TRACE(i);
    expect_hole(h[i], 1 + 0.5 * static_cast<double>(i), 1 + 0.25 * static_cast<double>(i), 0.04,
                -0.3, 0.5);
  }
}

TEST(Numeryx, EightHolesOnAPolarSlopeAtThirtyDegrees) {
  const auto h = holes_of(
      "g20\nfor #1=0 to 7\ng10 i1 j1 p30 r=gil(0.5,4) z.5 g81 r z-.3 f8\nnext #1 g80\nm30\n");
  ASSERT_EQ(h.size(), 8U);
  for (std::size_t i = 0; i < h.size(); ++i) {
    SCOPED_TRACE(i);
    const double radius = 0.5 + 0.5 * static_cast<double>(i);
    EXPECT_NEAR(h[i].x, 1 + radius * std::cos(M_PI / 6), 1e-12);
    EXPECT_NEAR(h[i].y, 1 + radius * std::sin(M_PI / 6), 1e-12);
  }
}

// "Note that we start from hole 1 and not 0 because there are 13 holes and hole 0 is the same
// as hole 13."
TEST(Numeryx, ThirteenHoleBoltCircle) {
  const auto h = holes_of(
      "g20\nfor #1=1 to 13\ng10 i j r4 p=gil(0,360) z.5 g81 r z-.3 f8\nnext #1 g80\nm30\n");
  ASSERT_EQ(h.size(), 13U);
  std::set<std::pair<long, long>> distinct;
  for (std::size_t i = 0; i < h.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_NEAR(std::hypot(h[i].x, h[i].y), 4, 1e-12);
    const double angle = std::atan2(h[i].y, h[i].x) * 180 / M_PI;
    const double expected = 360.0 / 13 * static_cast<double>(i + 1);
    EXPECT_NEAR(std::remainder(angle - expected, 360), 0, 1e-9);
    EXPECT_NEAR(h[i].bottom, -0.3, 1e-12);
    distinct.insert({std::lround(h[i].x * 1e6), std::lround(h[i].y * 1e6)});
  }
  EXPECT_EQ(distinct.size(), 13U);
  // Hole 13 is where hole 0 would be: at angle 0.
  EXPECT_NEAR(h[12].x, 4, 1e-12);
  EXPECT_NEAR(h[12].y, 0, 1e-12);
}

// --- errors and the dialect switch --------------------------------------------------------

TEST(Numeryx, ErrorsNameTheLineAndWhatIsWrong) {
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g81 z-5\nm30\n"),
            "nx.ngc:2:18: g81 needs R, the Z where drilling begins (r after g81)");
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g81 r2\nm30\n"),
            "nx.ngc:2:18: g81 needs Z, the bottom of the hole (z after g81)");
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g81 r2 z5\nm30\n"),
            "nx.ngc:2: The bottom of the hole (Z 5.0000) is not below R (Z 2.0000)");
  EXPECT_EQ(error_of("g x0 y0 z10 r2 f100 g81 z-5\nm30\n"),
            "nx.ngc:2:13: R word with no g2, g3 or g10 to use it (a drilling cycle's R, Z, Q "
            "and D are written after the cycle word: g81 r.. z..)");
  EXPECT_EQ(
      error_of("g x0 d2\nm30\n"),
      "nx.ngc:2:6: D word with no drilling cycle or G96 to use it (a drilling cycle's R, Z, Q "
      "and D are written after the cycle word: g81 r.. z..)");
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g87 r2 z-5\nm30\n"),
            "nx.ngc:2:18: g87 is no Numeryx drilling cycle (g73, g74, g81 to g86; g80 cancels)");
  EXPECT_EQ(error_of("g x0 y0 z10 g81 r2 z-5\nm30\n"), "nx.ngc:2: Cannot feed with zero feed rate");
  EXPECT_EQ(error_of("g x0 y0 z10 f100 g81 r2 z-5 g81\nm30\n"),
            "nx.ngc:2:29: Two drilling cycle words on one line");
}

TEST(Numeryx, TheDialectComesFromTheFirstLineOrTheMachine) {
  Outcome r = run("%\n(DIALECT Numeryx)\ng x1\n%\n");
  EXPECT_FALSE(r.error);
  EXPECT_EQ(r.dialect, Dialect::numeryx);
  InterpOptions options;
  options.dialect = Dialect::numeryx;
  r = run("g x1 y2\nm30\n", options);
  EXPECT_FALSE(r.error) << r.error->to_string();
  EXPECT_EQ(r.dialect, Dialect::numeryx);
  r = run("(dialect linuxcnc)\ng0 x1\nm30\n", options);
  EXPECT_FALSE(r.error);
  EXPECT_EQ(r.dialect, Dialect::linuxcnc);
  // Forced (cncd-check --dialect): the first line is an ordinary comment.
  options.dialect_from_first_line = false;
  r = run("(dialect linuxcnc)\ng x1\nm30\n", options);
  EXPECT_FALSE(r.error) << r.error->to_string();
  EXPECT_EQ(r.dialect, Dialect::numeryx);
  r = run("(dialect fanuc)\ng0 x1\nm30\n");
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->to_string(), "nx.ngc:1: Unknown dialect 'fanuc' (linuxcnc or numeryx)");
  // Without the dialect, Numeryx syntax is LinuxCNC's error.
  r = run("g x1\nm30\n");
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.dialect, Dialect::linuxcnc);
}

TEST(Numeryx, StateShowsTheCycleInForce) {
  Interpreter interp;
  ASSERT_FALSE(
      interp.open_string("(dialect numeryx)\ng x0 y0 z10 f100 g82 r0 z-5 d1 g99\n"
                         "g80\nm30\n"));
  Recorder recorder;
  ASSERT_EQ(interp.step(recorder), Interpreter::Step::block);  // the dialect line
  ASSERT_EQ(interp.step(recorder), Interpreter::Step::block);
  EXPECT_EQ(interp.state().gcodes[1], 820);
  EXPECT_EQ(interp.state().gcodes[10], 990);
  ASSERT_EQ(interp.step(recorder), Interpreter::Step::block);
  EXPECT_EQ(interp.state().gcodes[1], 0);     // back to the positioning mode
  EXPECT_EQ(interp.state().gcodes[10], 980);  // g80 cancelled g99
}

// The same program read both ways drills at different heights: the reason for the switch.
TEST(Numeryx, TheTwoReadingsOfOneProgramDiffer) {
  const std::string program = "g0 x0 y0 z10\nf100\ng81 r2 z-5\nx5\ng80\nm30\n";
  Outcome linuxcnc = run(program);
  ASSERT_FALSE(linuxcnc.error);
  Outcome numeryx = run("(dialect numeryx)\n" + program);
  ASSERT_FALSE(numeryx.error) << numeryx.error->to_string();
  const auto a = holes(linuxcnc.recorder.ops);
  const auto b = holes(numeryx.recorder.ops);
  ASSERT_EQ(a.size(), 2U);
  ASSERT_EQ(b.size(), 2U);
  expect_hole(a[0], 0, 0, 2, -5, 2);   // LinuxCNC: feeds from R, G99 by default
  expect_hole(b[0], 0, 0, 3, -5, 10);  // Numeryx: from R1 = R + 1, G98 by default
}

}  // namespace
}  // namespace cncd::interp
