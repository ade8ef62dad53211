// The Numeryx dialect against its application note (seed 002, An-101), continued: the syntax
// (bare g, '=' expressions, empty words, for/next, gil(), g10 polar), the note's examples, the
// errors and how a program's dialect is chosen.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "numeryx_fixture.hpp"

namespace cncd::interp {
namespace {

using namespace numeryx_test;

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
