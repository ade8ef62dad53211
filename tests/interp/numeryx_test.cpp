// The Numeryx dialect against every statement of its application note (seed 002, An-101):
// cycle heights, Zi, the cycle's own variables and distance mode, G98/G99/G80, D, units, the
// plane and tapping.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "numeryx_fixture.hpp"

namespace cncd::interp {
namespace {

using namespace numeryx_test;

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

}  // namespace
}  // namespace cncd::interp
