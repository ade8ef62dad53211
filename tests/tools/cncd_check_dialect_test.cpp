// cncd-check and the dialect: its summary says which one a program was read in and what chose
// it (--dialect, the program's first line, [RS274NGC] DIALECT), --dialect forces one, and the
// machine's DIALECT and NUMERYX_CLEARANCE reach the interpreter.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "cncd_check_fixture.hpp"

namespace cncd::test {
namespace {

// Read both ways: LinuxCNC feeds from R 2 (G99), Numeryx from R1 = R + clearance and returns
// to the initial Z 10 (G98). Valid in both dialects.
const std::string kCycle = "g0 x0 y0 z10\nf100\ng81 r2 z-5\nx5\ng80\nm30\n";

using CncdCheckDialect = CncdCheck;

// The first line of the summary.
std::string first_line(const std::string& out) {
  return out.substr(0, out.find('\n'));
}

// The top of the first hole --holes lists (its fifth column).
double first_top(const CommandResult& r) {
  EXPECT_EQ(r.exit_status, 0) << r.err;
  const auto row = r.out.find("\n    1 ");
  if (row == std::string::npos) {
    ADD_FAILURE() << r.out;
    return 0;
  }
  double hole = 0, line = 0, x = 0, y = 0, top = 0;
  std::sscanf(r.out.c_str() + row, "%lf %lf %lf %lf %lf", &hole, &line, &x, &y, &top);
  return top;
}

TEST_F(CncdCheckDialect, SummarySaysWhatChoseTheDialect) {
  auto r = check(kCycle, {"--ini", ini_.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(first_line(r.out), "dialect: linuxcnc ([RS274NGC] DIALECT)");
  EXPECT_NE(r.out.find("\nmoves: "), std::string::npos) << r.out;
  r = check(kCycle);
  EXPECT_EQ(first_line(r.out), "dialect: linuxcnc (default)");
  r = check("(dialect numeryx)\n" + kCycle, {"--ini", ini_.string()});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(first_line(r.out), "dialect: numeryx (the program's first line)");
  r = check("%\n(Dialect LinuxCNC)\n" + kCycle + "%\n",
            {"--ini", machine_with("DIALECT = numeryx\n")});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(first_line(r.out), "dialect: linuxcnc (the program's first line)");
  r = check(kCycle, {"--ini", machine_with("DIALECT = numeryx\n")});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(first_line(r.out), "dialect: numeryx ([RS274NGC] DIALECT)");
  // The rs274 format stays as LinuxCNC prints it.
  r = check(kCycle, {"--canon"});
  EXPECT_EQ(r.out.find("dialect"), std::string::npos) << r.out;
}

TEST_F(CncdCheckDialect, DialectOptionForcesOneWhateverTheFirstLineSays) {
  EXPECT_EQ(first_top(check(kCycle, {"--holes"})), 2);
  EXPECT_EQ(first_top(check(kCycle, {"--holes", "--dialect", "numeryx"})), 3);
  EXPECT_EQ(first_top(check("(dialect numeryx)\n" + kCycle, {"--holes"})), 3);
  EXPECT_EQ(first_top(check("(dialect numeryx)\n" + kCycle, {"--holes", "--dialect", "linuxcnc"})),
            2);
  auto r = check("(dialect numeryx)\n" + kCycle, {"--dialect", " LinuxCNC "});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(first_line(r.out), "dialect: linuxcnc (--dialect)");
  r = check(kCycle, {"--dialect", "numeryx", "--ini", machine_with("DIALECT = linuxcnc\n")});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_EQ(first_line(r.out), "dialect: numeryx (--dialect)");
  // Numeryx positioning ("g x1") is no LinuxCNC: forced, it is refused at its line.
  r = check("(dialect numeryx)\ng x1 y2 z10\nm30\n", {"--dialect", "linuxcnc"});
  EXPECT_EQ(r.exit_status, 1);
  EXPECT_NE(r.err.find("prog.ngc:2:"), std::string::npos) << r.err;
}

TEST_F(CncdCheckDialect, BadDialectIsAUsageError) {
  for (const char* bad : {"fanuc", "", "numeryx2"}) {
    const auto r = check(kCycle, {"--dialect", bad});
    EXPECT_EQ(r.exit_status, 2) << bad;
    EXPECT_NE(r.err.find("--dialect must be linuxcnc or numeryx"), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
  }
  const auto r = run_command({CNCD_CHECK_BINARY, "--dialect"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("--dialect needs a value"), std::string::npos) << r.err;
}

// The machine's dialect and clearance reach the interpreter: R1 = R + NUMERYX_CLEARANCE.
TEST_F(CncdCheckDialect, MachineDialectAndClearanceReachTheInterpreter) {
  EXPECT_EQ(first_top(check(kCycle, {"--holes", "--ini", machine_with("DIALECT = numeryx\n")})), 3);
  EXPECT_EQ(
      first_top(check(kCycle, {"--holes", "--ini",
                               machine_with("DIALECT = NUMERYX\nNUMERYX_CLEARANCE = 0.5\n")})),
      2.5);
  // The clearance serves programs that name the dialect on a LinuxCNC machine too.
  EXPECT_EQ(first_top(check("(dialect numeryx)\n" + kCycle,
                            {"--holes", "--ini", machine_with("NUMERYX_CLEARANCE = 0.25\n")})),
            2.25);
  const auto r = check(kCycle, {"--ini", machine_with("DIALECT = fanuc\n")});
  EXPECT_EQ(r.exit_status, 78);
  EXPECT_NE(r.err.find("[RS274NGC] DIALECT: unknown value 'fanuc'; expected one of linuxcnc, "
                       "numeryx"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace cncd::test
