// Values that outlive a block (coordinate system origins, G92 offsets, G28/G30 points, tool
// data, the tool length in force) are finite and at most 1e9 in size: a block that would store
// anything else is refused at its line and changes nothing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

// "LINE:COLUMN: message" of the program's error, or "" when it ran to the end.
std::string error_of(Interpreter& interp, const std::string& program) {
  NullSink sink;
  auto error = interp.open_string(program, "t.ngc");
  if (!error) error = run_program(interp, sink);
  if (!error) return "";
  return std::to_string(error->line) + ":" + std::to_string(error->column) + ": " + error->message;
}

std::string error_of(const std::string& program) {
  Interpreter interp;
  return error_of(interp, program);
}

// The error of one MDI block, or "".
std::string mdi_error(Interpreter& interp, const std::string& block) {
  NullSink sink;
  auto error = interp.open_mdi(block);
  if (!error) error = run_program(interp, sink);
  return error ? error->to_string() : "";
}

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

TEST(StoredValues, AssigningAHugeValueToAnOffsetParameterFailsAtItsLine) {
  Interpreter interp;
  const std::string error = error_of(interp, "G0 X0\n#5221=[10**299*10]\nG0 X1\nM2\n");
  EXPECT_EQ(error,
            "2:1: Parameter #5221 = 1e+300 is out of range: offsets, origins, stored positions "
            "and tool data must be finite and at most 1e9 in size");
  EXPECT_EQ(interp.coord_system_origin(1)[0], 0.0);
  // The bound itself is allowed.
  EXPECT_EQ(error_of("#5221=[10**9]\nG0 X1\nM2\n"), "");
  EXPECT_EQ(error_of("#5221=[-10**9]\nG0 X1\nM2\n"), "");
  // Parameters outside the persistent range may hold any finite value.
  EXPECT_EQ(error_of("#100=[10**299*10]\n#5400=0\nM2\n").find("1:"), std::string::npos);
}

TEST(StoredValues, ALineWithAnyBadAssignmentAssignsNothing) {
  Interpreter interp;
  EXPECT_TRUE(starts_with(mdi_error(interp, "#5222=7 #5221=[10**10]"), "MDI:1:9: Parameter #5221"))
      << mdi_error(interp, "#5222=7 #5221=[10**10]");
  EXPECT_EQ(interp.coord_system_origin(1)[1], 0.0);
}

TEST(StoredValues, ExpressionsThatAreNotFiniteNeverGetThatFar) {
  EXPECT_EQ(error_of("G10 L2 P1 X[1/0]\nM2\n"), "1:14: Attempt to divide by zero");
  EXPECT_TRUE(starts_with(error_of("#5221 = [1e300*1e300]\nM2\n"), "1:"));
  EXPECT_EQ(error_of("#5221=[10**300*10**300]\nM2\n"),
            "1:24: Result is not a finite number (overflow)");
}

// Each of the MDI `blocks` is refused because a value is beyond the bound, and unchanged()
// checks that it changed nothing.
template <typename Unchanged>
void expect_all_refused(Interpreter& interp, std::initializer_list<const char*> blocks,
                        Unchanged unchanged) {
  for (const char* block : blocks) {
    SCOPED_TRACE(block);
    const std::string error = mdi_error(interp, block);
    EXPECT_TRUE(starts_with(error, "MDI:1:")) << error;
    EXPECT_NE(error.find("out of range"), std::string::npos) << error;
    unchanged();
  }
}

TEST(StoredValues, G10OriginsBeyondTheBoundAreRefusedAndChangeNothing) {
  Interpreter interp;
  expect_all_refused(interp,
                     {"G10 L2 P1 X5 Y[10**10]", "G10 L20 P1 X5 Y[-10**10]",
                      "G10 L2 P1 X5 R[10**10]", "G10 L2 P2 X5 Y[10**299*10]"},
                     [&] {
                       double rotation = 0;
                       EXPECT_EQ(interp.coord_system_origin(1, &rotation)[0], 0.0);
                       EXPECT_EQ(interp.coord_system_origin(2)[0], 0.0);
                       EXPECT_EQ(rotation, 0.0);
                     });
  // In inches, the bound is on the machine's value (mm here).
  EXPECT_NE(mdi_error(interp, "G20 G10 L2 P1 X[10**9/25]").find("out of range"), std::string::npos);
  EXPECT_EQ(mdi_error(interp, "G21"), "");
}

TEST(StoredValues, G92AndG52BeyondTheBoundAreRefusedAndChangeNothing) {
  Interpreter interp;
  expect_all_refused(interp, {"G92 X[10**299*10]", "G92 X1 Y[-10**10]", "G52 Z[10**10]"}, [&] {
    const InterpState s = interp.state();
    for (double v : s.g92_offset)
      EXPECT_EQ(v, 0.0);
    EXPECT_EQ(s.gcodes[16], -1);  // G92 not switched on either
  });
  // The machine still answers normally after the refusals.
  EXPECT_EQ(mdi_error(interp, "G92 X2"), "");
  EXPECT_EQ(interp.state().g92_offset[0], -2.0);
}

TEST(StoredValues, ToolDataAndToolLengthsBeyondTheBoundAreRefused) {
  Interpreter interp;
  expect_all_refused(interp,
                     {"G10 L1 P1 Z[10**10]", "G10 L10 P1 Z[-10**10]", "G10 L11 P1 Z[10**299*10]",
                      "G10 L1 P1 Z1 R[10**10]"},
                     [&] { EXPECT_FALSE(interp.tool(1).has_value()); });
  EXPECT_EQ(mdi_error(interp, "G10 L1 P1 Z5"), "");
  expect_all_refused(interp, {"G43.1 Z[10**10]", "G43.1 X[-10**299*10]"},
                     [&] { EXPECT_EQ(interp.state().tool_offset[2], 0.0); });
}

TEST(StoredValues, StoredPositionsBeyondTheBoundAreRefused) {
  // G28.1 stores where the program stands: not a point no machine can reach.
  EXPECT_NE(error_of("G0 X[10**10]\nG28.1\nM2\n").find("2:1: Parameter #5161"), std::string::npos)
      << error_of("G0 X[10**10]\nG28.1\nM2\n");
}

TEST(StoredValues, AMoveToAPointThatIsNotFiniteIsRefusedAtItsLine) {
  // Each pass adds 1e306 to X: the 180th overflows.
  const std::string error =
      error_of("#1=[10**306]\no1 repeat [200]\nG91 G0 X#1\no1 endrepeat\nM2\n");
  EXPECT_TRUE(starts_with(error, "3:")) << error;
  EXPECT_NE(error.find("not a finite number"), std::string::npos) << error;
}

TEST(StoredValues, AToolTableHoldingValuesThatAreNotStorableIsRefusedWithItsLine) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("cncd_stored_" + std::to_string(::getpid()) + ".tbl");
  for (const char* line : {"T2 P2 Znan", "T2 P2 Z-inf", "T2 P2 X1e10", "T2 P2 Z1 D1e300"}) {
    SCOPED_TRACE(line);
    std::ofstream(path) << "T1 P1 Z1 ;fine\n" << line << " ;bad\n";
    InterpOptions options;
    options.tool_table = path;
    const Interpreter interp(options);
    ASSERT_TRUE(interp.load_error().has_value());
    const std::string message = interp.load_error()->message;
    EXPECT_TRUE(starts_with(message, path.string() + ":2: Tool 2 ")) << message;
    EXPECT_NE(message.find("out of range"), std::string::npos) << message;
    EXPECT_TRUE(interp.tools().empty());
  }
  std::filesystem::remove(path);
}

TEST(StoredValues, OriginsAndToolsSetBetweenProgramsAreCheckedToo) {
  Interpreter interp;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {nan, inf, -inf, 1e300, -1.5e9}) {
    SCOPED_TRACE(bad);
    EXPECT_TRUE(interp.set_coord_system_origin(1, Pose{5, bad}, 0b11, std::nullopt));
    EXPECT_TRUE(interp.set_coord_system_origin(2, Pose{}, 0, bad));
    double rotation = 0;
    EXPECT_EQ(interp.coord_system_origin(1)[0], 0.0);
    EXPECT_EQ(interp.coord_system_origin(2, &rotation)[0], 0.0);
    EXPECT_EQ(rotation, 0.0);
    ToolEntry tool;
    tool.number = 3;
    tool.pocket = 3;
    tool.offset[2] = bad;
    EXPECT_TRUE(interp.set_tool(tool));
    tool.offset[2] = 0;
    tool.diameter = bad;
    EXPECT_TRUE(interp.set_tool(tool));
    EXPECT_FALSE(interp.tool(3).has_value());
  }
  EXPECT_FALSE(interp.set_coord_system_origin(1, Pose{5}, 0b1, 10.0));
  EXPECT_EQ(interp.coord_system_origin(1)[0], 5.0);
}

}  // namespace
}  // namespace cncd::interp
