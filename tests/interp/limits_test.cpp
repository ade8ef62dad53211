// Hostile programs get clear errors at the right line, never a crash or a hang: deep nesting,
// huge and non-finite numbers, endless loops and recursion, huge integer words (the last found
// by the fuzzer: G10 L1 P with 60 digits overflowed the conversion to int).
#include <gtest/gtest.h>

#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

// Runs `program`; returns "LINE:COLUMN: message" of its error, or "" when it ran to the end.
std::string error_of(const std::string& program, InterpOptions options = {}) {
  Interpreter interp(options);
  NullSink sink;
  auto error = interp.open_string(program, "t.ngc");
  if (!error) error = run_program(interp, sink);
  if (!error) return "";
  return std::to_string(error->line) + ":" + std::to_string(error->column) + ": " + error->message;
}

std::string digits(char digit, int count) {
  return std::string(static_cast<std::size_t>(count), digit);
}

TEST(InterpLimits, DeepNestingIsRefusedPastOneHundredLevels) {
  EXPECT_EQ(error_of("G0 X" + std::string(99, '[') + "1" + std::string(99, ']') + "\nM2\n"), "");
  const std::string deep =
      "G0 X" + std::string(1000, '[') + "1" + std::string(1000, ']') + "\nM2\n";
  EXPECT_EQ(error_of(deep), "1:105: Expression nested too deeply (more than 100 levels)");
  EXPECT_EQ(error_of("G0 X" + std::string(200, '-') + "1\nM2\n").find("1:"), 0u);
}

TEST(InterpLimits, HugeAndNonFiniteNumbersAreRefused) {
  // No exponents: "e299" is an E word, which a G0 has no use for (rs274's message too).
  EXPECT_EQ(error_of("G0 X1e299\nM2\n"), "1:6: E word with no G70, G76, M66, M67 or M68 to use it");
  EXPECT_EQ(error_of("G0 X" + digits('9', 300) + "\nM2\n"), "");
  EXPECT_EQ(error_of("G0 X" + digits('9', 301) + "\nM2\n"),
            "1:5: Number too large (more than 1e300)");
  EXPECT_EQ(error_of("G0 X" + digits('9', 400) + "\nM2\n"),
            "1:5: Number too large (more than 1e300)");
  EXPECT_EQ(error_of("#1=[10**300*10**300]\nG0 X#1\nM2\n"),
            "1:21: Result is not a finite number (overflow)");
  EXPECT_EQ(error_of("G0 X[EXP[1000]]\nM2\n"), "1:15: Result is not a finite number (overflow)");
}

TEST(InterpLimits, EndlessLoopsWithoutMotionAndEndlessRecursionStop) {
  InterpOptions options;
  EXPECT_EQ(options.max_loops_without_motion, 1'000'000u);
  options.max_loops_without_motion = 1000;
  EXPECT_EQ(error_of("o1 while [1]\no1 endwhile\nM2\n", options),
            "2:0: Endless loop: 1000 loop iterations without a move or dwell");
  EXPECT_EQ(error_of("o1 do\no1 while [1]\nM2\n", options),
            "2:0: Endless loop: 1000 loop iterations without a move or dwell");
  EXPECT_EQ(error_of("o1 repeat [1000000000]\no1 continue\no1 endrepeat\nM2\n", options),
            "2:0: Endless loop: 1000 loop iterations without a move or dwell");
  // A loop that moves is a program, however long.
  EXPECT_EQ(error_of("#1=0\no1 while [#1 LT 2000]\nG0 X#1\n#1=[#1+1]\no1 endwhile\nM2\n", options),
            "");
  EXPECT_EQ(error_of("o<r> sub\no<r> call\no<r> endsub\no<r> call\nM2\n"),
            "2:0: Too many nested subroutine calls");
}

TEST(InterpLimits, HugeIntegerWordsFailTheirRangeChecks) {
  const std::string huge = digits('8', 60);
  EXPECT_EQ(error_of("G10 L2 P" + huge + " X1\nM2\n"),
            "1:0: P value out of range (0-9) with G10 L2");
  EXPECT_EQ(error_of("G10 L" + huge + " P1 X1\nM2\n"), "1:6: Non integer value for integer");
  // G10 L1 P<huge>: clamped, the table takes tool 2000000000 (no overflow).
  EXPECT_EQ(error_of("G10 L1 P1" + huge + " Z2 R0.5\nM2\n"), "");
  EXPECT_NE(error_of("G81 X1 Z-1 R1 F10 L" + huge + "\nM2\n"), "");
}

TEST(InterpLimits, ACycleBlockExpandsIntoABoundedNumberOfMoves) {
  // Found by the fuzzer: a G83 whose Q is too small to change the depth in floating point
  // pecked forever inside one block.
  EXPECT_EQ(error_of("G0 Z100000000000000000\n"
                     "G83 X1 Z99999999999990000 R100000000000000000 Q0.2 F10\nM2\n"),
            "2:0: Too many pecks in g83: Q too small for the depth (more than 100000 pecks)");
  EXPECT_EQ(error_of("G0 Z1\nG73 X1 Z-10 R0 Q0.00001 F10\nM2\n"),
            "2:0: Too many pecks in g73: Q too small for the depth (more than 100000 pecks)");
  EXPECT_EQ(error_of("G0 Z1\nG83 X1 Z-10 R0 Q0.001 F10\nM2\n"), "");  // 10,000 pecks
  EXPECT_EQ(error_of("G91 G0 Z1\nG81 X1 Z-1 R0 F10 L100001\nM2\n"),
            "2:19: Too many repeats of cycle (L more than 100000)");
}

TEST(InterpLimits, ASubroutineNameTooLongForAFileIsNotFound) {
  // Found by the fuzzer: the file lookup threw "File name too long" out of the interpreter.
  const std::string error = error_of("o<" + std::string(300, 'a') + "> call\nM2\n");
  EXPECT_EQ(error.rfind("1:0: ", 0), 0u) << error;
  EXPECT_NE(error.find("o<aaaa"), std::string::npos) << error.substr(0, 80);
}

}  // namespace
}  // namespace cncd::interp
