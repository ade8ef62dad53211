// Expressions, parameters and line syntax, checked through the canonical output.
#include <gtest/gtest.h>

#include <initializer_list>
#include <sstream>
#include <string>
#include <utility>
#include <variant>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

// Runs `line` after G0 and returns the X of the traverse it makes.
double x_of(const std::string& expression) {
  Interpreter interp;
  EXPECT_FALSE(interp.open_string("G0 X" + expression + "\nM2\n", "expr.ngc"));
  struct Sink final : CanonSink {
    void emit(const CanonCommand& command) override {
      if (const auto* traverse = std::get_if<StraightTraverse>(&command.op)) x = traverse->end[0];
    }
    double x = -999;
  } sink;
  const auto error = run_program(interp, sink);
  EXPECT_FALSE(error) << (error ? error->to_string() : "");
  return sink.x;
}

std::string error_of(const std::string& program) {
  Interpreter interp;
  EXPECT_FALSE(interp.open_string(program, "e.ngc"));
  NullSink sink;
  const auto error = run_program(interp, sink);
  return error ? error->message : std::string();
}

// The canonical commands of `program`, which must run to its end, as rs274 prints them.
std::string canon_of(const std::string& program, const std::string& name = "<mdi>") {
  Interpreter interp;
  EXPECT_FALSE(interp.open_string(program, name));
  std::ostringstream out;
  Rs274Printer printer(out);
  const auto error = run_program(interp, printer);
  EXPECT_FALSE(error) << error->to_string();
  return out.str();
}

// Each program's first error as LinuxCNC words it ("" when it runs to its end).
void expect_errors(std::initializer_list<std::pair<const char*, const char*>> cases) {
  for (const auto& [program, message] : cases)
    EXPECT_EQ(error_of(program), message) << program;
}

TEST(Expressions, PrecedenceIsLinuxCncs) {
  EXPECT_DOUBLE_EQ(x_of("[2**3+1*2 EQ 10]"), 1.0);
  EXPECT_DOUBLE_EQ(x_of("[2**3**2]"), 64.0);  // left-associative
  EXPECT_DOUBLE_EQ(x_of("[2 - 3 - 4]"), -5.0);
  EXPECT_DOUBLE_EQ(x_of("[1 + 2 EQ 3]"), 1.0);
  EXPECT_DOUBLE_EQ(x_of("[1 EQ 1.00001]"), 1.0);  // EQ compares with a tolerance
}

TEST(Expressions, ModTakesTheSignOfNothing) {
  EXPECT_DOUBLE_EQ(x_of("[-7 MOD 3]"), 2.0);
  EXPECT_DOUBLE_EQ(x_of("[7 MOD -3]"), 1.0);
}

TEST(Expressions, FunctionsWorkInDegrees) {
  EXPECT_NEAR(x_of("sin[30]"), 0.5, 1e-12);
  EXPECT_NEAR(x_of("[atan[1]/[1]]"), 45.0, 1e-12);
  EXPECT_DOUBLE_EQ(x_of("[fix[-1.5]]"), -2.0);
  EXPECT_DOUBLE_EQ(x_of("[fup[1.2]]"), 2.0);
  EXPECT_DOUBLE_EQ(x_of("[round[2.5]]"), 3.0);
  EXPECT_DOUBLE_EQ(x_of("[abs[-2]]"), 2.0);
  EXPECT_DOUBLE_EQ(x_of("[sqrt[16]]"), 4.0);
}

TEST(Expressions, UnaryMinusBeforeParameterOrBracket) {
  const std::string canon = canon_of("#1=2\nG0 X-#1 Y-[1+2]\nM2\n");
  EXPECT_NE(canon.find("STRAIGHT_TRAVERSE(-2.0000, -3.0000, 0.0000"), std::string::npos);
}

TEST(Parameters, AssignmentTakesEffectAfterTheLine) {
  EXPECT_DOUBLE_EQ(x_of("#1"), 0.0);
  const std::string canon = canon_of("#1=5 G0 X#1\nG0 Y#1\nM2\n");
  EXPECT_NE(canon.find("STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000"), std::string::npos);
  EXPECT_NE(canon.find("STRAIGHT_TRAVERSE(0.0000, 5.0000, 0.0000"), std::string::npos);
}

TEST(Errors, Wording) {
  expect_errors({
      {"G0 X[1/0]\nM2\n", "Attempt to divide by zero"},
      {"G0 G1 X1\nM2\n", "Two g codes used from same modal group"},
      {"M3 M4\nM2\n", "Two m codes used from same modal group"},
      {"G7.5\nM2\n", "Unknown g code used"},
      {"F-1\nM2\n", "Negative f word used"},
      {"X1\nM2\n", "Cannot use axis values without a g code that uses them"},
  });
}

TEST(Comments, LastCommentOfALineAndMessages) {
  const std::string canon = canon_of("(first)(second)\n(MSG, Hello There)\nG0 X1 ; trailing\nM2\n");
  EXPECT_NE(canon.find("COMMENT(\"second\")"), std::string::npos);
  EXPECT_EQ(canon.find("COMMENT(\"first\")"), std::string::npos);
  EXPECT_NE(canon.find("MESSAGE(\" Hello There\")"), std::string::npos);
}

// (ABORT, ...) stops the program with its message. rs274 reports an empty one as "Unknown
// error, bad error code"; cncd says what stopped it.
TEST(Comments, AnAbortWithoutAMessageSaysWhatStoppedTheProgram) {
  expect_errors({
      {"(abort,)\nM2\n", "Program aborted by an (ABORT,) comment without a message"},
      {"(abort, )\nM2\n", " "},
      {"#1 = 2\n(Abort,#1)\nM2\n", "2.000000"},
  });
}

// rs274 creates a named parameter as soon as it reads "#<b> =", so EXISTS on that line says 1
// (and reading #<b> there gives 0). Its value comes only after the line: cncd says it does not
// exist yet, as reading it there is an error.
TEST(Exists, AParameterTheLineAssignsDoesNotExistYetOnThatLine) {
  EXPECT_DOUBLE_EQ(x_of("[EXISTS[#<new>]] #<new> = 1"), 0.0);
  EXPECT_EQ(error_of("#<b> = 1 #21 = EXISTS[#<b>]\nG0 X#21\nM2\n"), "");
  EXPECT_NE(canon_of("#<b> = 1 #21 = EXISTS[#<b>]\nG0 X#21\nM2\n").find("TRAVERSE(0.0000,"),
            std::string::npos);
  EXPECT_EQ(error_of("#<b> = 1 #21 = #<b>\nM2\n"), "Named parameter #<b> not defined");
}

// Fanuc-style posts put the program number first: LinuxCNC ignores a bare O-word, and the
// comments after it.
TEST(ProgramNumbers, ABareOWordIsIgnoredWithItsComments) {
  const std::string canon =
      canon_of("%\nO0001 (PART NAME)\nN5 O0002\no<named> (MSG,hidden)\nO3 ;note\nG0 X1\nM2\n%\n",
               "number.ngc");
  EXPECT_EQ(canon.find("COMMENT"), std::string::npos) << canon;
  EXPECT_EQ(canon.find("MESSAGE"), std::string::npos) << canon;
  EXPECT_NE(canon.find("STRAIGHT_TRAVERSE(1.0000"), std::string::npos) << canon;
}

TEST(ProgramNumbers, AnythingButACommentAfterABareOWordIsRefused) {
  expect_errors({
      {"O0001 G0 X1\nM2\n", "Unknown control command in o word"},
      {"O0001 X1\nM2\n", "Unknown control command in o word"},
      {"O0001 (NAME) G0 X1\nM2\n", "Unexpected character after O-word"},
      {"O0001 (NAME\nM2\n", "Unclosed comment found"},
      {"O0001 (a(b))\nM2\n", "Nested comment found"},
      // Only block delete and a line number may come before an O-word.
      {"G0 X1 O0001\nM2\n", "Bad character 'o' used"},
      {"(NAME) O0001\nM2\n", "Bad character 'o' used"},
      {"G0 X1 O100 call\nM2\n", "Bad character 'o' used"},
      {"/N10 O0001\nM2\n", ""},
  });
}

// rs274 converts an O-word number past the int range without a check: o[3000000000] calls
// o<-2147483648>. Such a name is refused instead.
TEST(OWordNumbers, ANumberPastTheIntRangeIsRefused) {
  expect_errors({
      {"o[3000000000] call\nM2\n", "O-word number out of range (at most 2147483647 in size)"},
      {"#1 = -2147483648\no#1 sub\no#1 endsub\nM2\n",
       "O-word number out of range (at most 2147483647 in size)"},
      {"o[2147483647] sub\no2147483647 endsub\no[2147483647] call\nM2\n", ""},
      {"o[-2147483647] sub\no<-2147483647> endsub\no[-2147483647] call\nM2\n", ""},
  });
}

}  // namespace
}  // namespace cncd::interp
