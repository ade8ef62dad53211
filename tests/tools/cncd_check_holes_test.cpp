// cncd-check --holes: the holes a program drills, worked out by hand from each program, found
// in the moves whatever made them (G81, G83's pecks, a G1 plunge), in machine coordinates and
// units.
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd_check_fixture.hpp"

namespace cncd::test {
namespace {

struct Row {
  int hole = 0;
  int line = 0;
  double x = 0, y = 0, top = 0, bottom = 0;
};

// The rows of --holes output after its two header lines; the first line is kept in `header`.
std::vector<Row> rows(const std::string& out, std::string* header = nullptr) {
  std::istringstream in(out);
  std::string text;
  std::getline(in, text);
  if (header != nullptr) *header = text;
  std::getline(in, text);
  EXPECT_EQ(text, " hole    line            X            Y          top       bottom");
  std::vector<Row> result;
  while (std::getline(in, text)) {
    Row r;
    std::istringstream fields(text);
    fields >> r.hole >> r.line >> r.x >> r.y >> r.top >> r.bottom;
    EXPECT_TRUE(fields) << text;
    result.push_back(r);
  }
  return result;
}

void expect_row(const Row& r, int hole, int line, double x, double y, double top, double bottom) {
  SCOPED_TRACE("hole " + std::to_string(hole));
  EXPECT_EQ(r.hole, hole);
  EXPECT_EQ(r.line, line);
  EXPECT_NEAR(r.x, x, 1e-4);
  EXPECT_NEAR(r.y, y, 1e-4);
  EXPECT_NEAR(r.top, top, 1e-4);
  EXPECT_NEAR(r.bottom, bottom, 1e-4);
}

using CncdCheckHoles = CncdCheck;

// examples/g81_example1.ngc: G0 X1 Y2 Z3 (line 6), then G98 G81 X4 Y5 Z1.5 R2.8 (line 7):
// a rapid to X4 Y5, down to R 2.8, the feed to 1.5 and the rapid back to the old Z 3. One
// hole, fed from 2.8 to 1.5.
TEST_F(CncdCheckHoles, G81ExampleHasItsOneHole) {
  const std::string program = std::string(CNCD_SOURCE_DIR) + "/examples/g81_example1.ngc";
  const auto r = run_command({CNCD_CHECK_BINARY, "--holes", "--ini", ini_.string(), program});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(r.out,
            "holes: 1 (machine coordinates, mm)\n"
            " hole    line            X            Y          top       bottom\n"
            "    1       7       4.0000       5.0000       2.8000       1.5000\n");
}

// G83 from R 2 to Z -6 in pecks of 2.5 mm: feeds to -0.5, -3, -5.5 and -6 with rapids up to R
// and back down between them, at each of two positions. One hole per position, from the top
// of the first peck to the last.
TEST_F(CncdCheckHoles, PeckDrillingIsOneHolePerPosition) {
  const std::string program =
      "G21 G90 G98\nG0 X0 Y0 Z10\nG83 X5 Y5 Z-6 R2 Q2.5 F100\nX15\nG80\nM2\n";
  const auto summary = check(program, {"--ini", ini_.string()});
  ASSERT_EQ(summary.exit_status, 0) << summary.err;
  // Four feeds a hole: the pecks are there, and counted as one hole each time.
  EXPECT_NE(summary.out.find(", 8 feed, "), std::string::npos) << summary.out;
  const auto r = check(program, {"--holes", "--ini", ini_.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::string header;
  const auto holes = rows(r.out, &header);
  EXPECT_EQ(header, "holes: 2 (machine coordinates, mm)");
  ASSERT_EQ(holes.size(), 2U) << r.out;
  expect_row(holes[0], 1, 3, 5, 5, 2, -6);
  expect_row(holes[1], 2, 4, 15, 5, 2, -6);
}

// A hole drilled with G1: the second plunge at the same XY goes on with it; a rapid down is
// no hole; a feed down followed by a cut along X is a hole (the plunge), the cut is not.
TEST_F(CncdCheckHoles, AG1PlungeIsAHole) {
  const auto r = check(
      "G21 G90\n"
      "G0 X1 Y1 Z5\n"  // 2
      "G1 Z-2 F50\n"   // 3: hole 1 from 5
      "G0 Z1\n"        // 4
      "G1 Z-3\n"       // 5: deeper, the same hole
      "G0 Z5\n"        // 6
      "G0 X2 Z0\n"     // 7
      "G0 Z-1\n"       // 8: a rapid down: no hole
      "G0 Z5\n"        // 9
      "G0 X3\n"        // 10
      "G1 Z-1\n"       // 11: hole 2 from 5
      "G1 X4\n"        // 12: a cut, not a hole
      "G1 Z-1.5 X5\n"  // 13: a ramp, not a hole
      "G1 Z2\n"        // 14: up
      "G0 Z5\nM2\n",
      {"--holes", "--ini", ini_.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto holes = rows(r.out);
  ASSERT_EQ(holes.size(), 2U) << r.out;
  expect_row(holes[0], 1, 3, 1, 1, 5, -3);
  expect_row(holes[1], 2, 11, 3, 1, 5, -1);
}

// Machine coordinates and units, as the summary's extents and --trajectory: a G20 program
// with a G54 origin at X100 on this mm machine.
TEST_F(CncdCheckHoles, HolesAreInMachineCoordinatesAndUnits) {
  const auto r = check(
      "G21 G10 L2 P1 X100 Y0 Z0\nG20 G90 G54 G98\nG0 X1 Y1 Z0.5\nG81 Z-0.1 R0.1 F10\nG80\nM2\n",
      {"--holes", "--ini", ini_.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  std::string header;
  const auto holes = rows(r.out, &header);
  EXPECT_EQ(header, "holes: 1 (machine coordinates, mm)");
  ASSERT_EQ(holes.size(), 1U) << r.out;
  expect_row(holes[0], 1, 4, 100 + 25.4, 25.4, 2.54, -2.54);
}

TEST_F(CncdCheckHoles, NoHolesAndBadCombinations) {
  auto r = check("G0 X1 Y1 Z1\nG1 X5 F100\nM2\n", {"--holes"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(r.out,
            "holes: 0 (machine coordinates, mm)\n"
            " hole    line            X            Y          top       bottom\n");
  EXPECT_EQ(check("M2\n", {"--holes", "--canon"}).exit_status, 2);
  r = check("M2\n", {"--holes", "--plan", "--ini", ini_.string()});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--holes goes without --plan and --canon"), std::string::npos) << r.err;
}

// A program the interpreter stops on lists the holes before the error, and fails.
TEST_F(CncdCheckHoles, HolesBeforeAnErrorAreListed) {
  const auto r = check("G21 G90 G98\nG0 X0 Y0 Z5\nG81 X1 Z-1 R1 F100\nG82 X2 Z-1 R1\nM2\n",
                       {"--holes", "--ini", ini_.string()});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("prog.ngc:4:"), std::string::npos) << r.err;
  const auto holes = rows(r.out);
  ASSERT_EQ(holes.size(), 1U) << r.out;
  expect_row(holes[0], 1, 3, 1, 0, 1, -1);
}

}  // namespace
}  // namespace cncd::test
