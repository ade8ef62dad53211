// Program I/O: M62-M65 digital and M67/M68 analog outputs, the M66 wait and #5399, and the user
// M codes M100-M199 found in InterpOptions::user_m_path. What rs274 can show is in the goldens
// (tests/golden/io_*, error_io_*); these check the typed commands, cncd's index ranges, the
// machine's answer to M66 and the user M codes, which LinuxCNC's rs274 cannot run.
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "canon_recorder.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

using Recorder = test_support::CanonRecorder;

Recorder run(const std::string& program, InterpOptions options = {}) {
  Interpreter interp(std::move(options));
  Recorder recorder;
  EXPECT_FALSE(interp.open_string(program, "io.ngc"));
  const auto error = run_program(interp, recorder);
  EXPECT_FALSE(error) << error->to_string();
  return recorder;
}

// "LINE:COLUMN: message", or "" when the program ran to its end.
std::string error_of(const std::string& program, InterpOptions options = {}) {
  Interpreter interp(std::move(options));
  NullSink sink;
  auto error = interp.open_string(program, "io.ngc");
  if (!error) error = run_program(interp, sink);
  if (!error) return "";
  return std::to_string(error->line) + ":" + std::to_string(error->column) + ": " + error->message;
}

TEST(InterpIo, OutputsBecomeTypedCommands) {
  const auto r = run("M62 P3\nM63 P3\nM64 P31\nM65 P0\nM67 E2 Q1.5\nM68 E15 Q-2\nM67 E1\nM2\n");
  const auto bits = r.all<SetOutputBit>();
  ASSERT_EQ(bits.size(), 4u);
  EXPECT_EQ(bits[0].index, 3);
  EXPECT_TRUE(bits[0].on);
  EXPECT_TRUE(bits[0].motion);
  EXPECT_FALSE(bits[1].on);
  EXPECT_TRUE(bits[1].motion);
  EXPECT_EQ(bits[2].index, 31);
  EXPECT_TRUE(bits[2].on);
  EXPECT_FALSE(bits[2].motion);
  EXPECT_FALSE(bits[3].on);
  EXPECT_FALSE(bits[3].motion);
  const auto values = r.all<SetOutputValue>();
  ASSERT_EQ(values.size(), 3u);
  EXPECT_EQ(values[0].index, 2);
  EXPECT_EQ(values[0].value, 1.5);
  EXPECT_TRUE(values[0].motion);
  EXPECT_EQ(values[1].index, 15);
  EXPECT_EQ(values[1].value, -2.0);
  EXPECT_FALSE(values[1].motion);
  EXPECT_EQ(values[2].value, -1.0);  // no Q: LinuxCNC's -1
}

// M428 and M429, LinuxCNC's sample remaps for table-rotary kinematics, switch TCP on and off
// before the block's motion; no other code above M199 is known.
TEST(InterpIo, M428AndM429SwitchTcpBeforeTheMove) {
  const auto r = run("M428 G0 X1\nM429\nM2\n");
  const auto switches = r.all<SetTcp>();
  ASSERT_EQ(switches.size(), 2u);
  EXPECT_TRUE(switches[0].on);
  EXPECT_FALSE(switches[1].on);
  // The switch comes before the traverse of its block.
  std::size_t tcp_at = r.commands.size(), traverse_at = r.commands.size();
  for (std::size_t k = r.commands.size(); k-- > 0;) {
    if (std::holds_alternative<SetTcp>(r.commands[k].op)) tcp_at = k;
    if (std::holds_alternative<StraightTraverse>(r.commands[k].op)) traverse_at = k;
  }
  EXPECT_LT(tcp_at, traverse_at);
  EXPECT_EQ(error_of("M430\nM2\n"), "1:1: M-code greater than 199: M430");
  EXPECT_EQ(error_of("M428 M429\nM2\n"), "1:6: Two m codes used from same modal group");
}

// With a machine that says where the switch puts the tool (InterpOptions::tcp_switch: here a
// table turned 90 degrees, X Y -> Y -X, and a G54 offset of X 5), the program goes on from
// there in the new frame: a move of Z alone after M428 leaves X and Y where the tool stands.
TEST(InterpIo, M428AndM429GoOnFromWhereTheSwitchPutsTheTool) {
  InterpOptions options;
  int switches = 0;
  options.tcp_switch = [&](const Pose& machine, bool on) {
    ++switches;
    Pose moved = machine;
    moved[0] = on ? machine[1] : -machine[1];
    moved[1] = on ? -machine[0] : machine[0];
    return moved;
  };
  const auto r = run("G10 L2 P1 X5\nG54 G0 X5 Y0 Z2\nM428\nG1 Z0 F100\nM429\nG1 Z2\nM2\n", options);
  EXPECT_EQ(switches, 2);
  const auto feeds = r.all<StraightFeed>();
  ASSERT_EQ(feeds.size(), 2u);
  // Machine X 10 Y 0 is X 0 Y -10 in the turned frame: program X -5 with the offset.
  EXPECT_NEAR(feeds[0].end[0], -5, 1e-12);
  EXPECT_NEAR(feeds[0].end[1], -10, 1e-12);
  EXPECT_NEAR(feeds[0].end[2], 0, 1e-12);
  EXPECT_NEAR(feeds[1].end[0], 5, 1e-12);
  EXPECT_NEAR(feeds[1].end[1], 0, 1e-12);
  EXPECT_NEAR(feeds[1].end[2], 2, 1e-12);
  // Where the position would jump under the compensated path: refused at the M code.
  EXPECT_EQ(error_of("G0 X0 Y0\nG41 D1 G1 X10 F100\nM428\nM2\n", options),
            "3:1: Cannot switch TCP (M428) with cutter radius compensation on");
}

TEST(InterpIo, OutputsComeBeforeTheToolChangeAndTheMove) {
  const auto r = run("T1 M6 M3 M62 P1 G0 X1\nM2\n");
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < r.commands.size(); ++i) {
    const auto& op = r.commands[i].op;
    if (std::holds_alternative<SelectTool>(op) || std::holds_alternative<SetOutputBit>(op) ||
        std::holds_alternative<StartChange>(op) ||
        std::holds_alternative<StartSpindleClockwise>(op) ||
        std::holds_alternative<StraightTraverse>(op)) {
      order.push_back(r.commands[i].op.index());
    }
  }
  const std::vector<std::size_t> expected{
      CanonOp(SelectTool{}).index(), CanonOp(SetOutputBit{}).index(),
      CanonOp(StartChange{}).index(), CanonOp(StartSpindleClockwise{}).index(),
      CanonOp(StraightTraverse{}).index()};
  EXPECT_EQ(order, expected);
}

TEST(InterpIo, IndexesOutsideWhatCncdHasAreErrorsNamingThem) {
  EXPECT_EQ(error_of("M62 P32\nM2\n"),
            "1:5: Digital output index out of range with M62: 32 not in [0..31]");
  EXPECT_EQ(error_of("G0 X1\nM65 P-1\nM2\n"),
            "2:5: Digital output index out of range with M65: -1 not in [0..31]");
  EXPECT_EQ(error_of("M64 P31.6\nM2\n"),
            "1:5: Digital output index out of range with M64: 32 not in [0..31]");
  EXPECT_EQ(error_of("M67 E16 Q1\nM2\n"), "1:5: Invalid analog index with M67: 16 not in [0..15]");
  EXPECT_EQ(error_of("M68 E-1 Q1\nM2\n"), "1:1: Invalid analog index with M68");
  EXPECT_EQ(error_of("M66 P32\nM2\n"),
            "1:5: Digital input selected out of bounds: 32 not in [0..31]");
  EXPECT_EQ(error_of("M66 E16\nM2\n"),
            "1:5: Analog input selected out of bounds: 16 not in [0..15]");
  EXPECT_EQ(error_of("M66 P1 L5 Q1\nM2\n"),
            "1:8: Unknown Wait Mode with M66 (0 immediate, 1 rise, 2 fall, 3 high, 4 low): 5 not "
            "in [0..4]");
  // Nothing of the refused block happens.
  Interpreter interp;
  Recorder r;
  ASSERT_FALSE(interp.open_string("M62 P40 G0 X5\nM2\n", "io.ngc"));
  EXPECT_TRUE(run_program(interp, r));
  EXPECT_TRUE(r.all<StraightTraverse>().empty());
}

TEST(InterpIo, M66BecomesAWaitInput) {
  const auto r = run("M66 P2 L3 Q2.5\nM66 P4\nM66 P5 L0 Q-3\nM66 E1 Q5\nM66 E2.5 L0\nM2\n");
  const auto waits = r.all<WaitInput>();
  ASSERT_EQ(waits.size(), 5u);
  EXPECT_EQ(waits[0].index, 2);
  EXPECT_TRUE(waits[0].digital);
  EXPECT_EQ(waits[0].mode, 3);
  EXPECT_EQ(waits[0].timeout_s, 2.5);
  EXPECT_EQ(waits[1].mode, 0);
  EXPECT_EQ(waits[1].timeout_s, 0.0);
  EXPECT_EQ(waits[2].timeout_s, 0.0);  // a Q not above 0 is no timeout
  EXPECT_FALSE(waits[3].digital);
  EXPECT_EQ(waits[3].index, 1);
  EXPECT_EQ(waits[3].mode, 0);
  EXPECT_EQ(waits[3].timeout_s, 0.0);  // an analog input is read at once
  EXPECT_EQ(waits[4].index, 2);        // E2.5: halves to even
  // rs274 prints nothing for the wait; neither does the printer.
  EXPECT_EQ(format_rs274(CanonCommand{1, WaitInput{1, true, 3, 2.0}}), "");
  std::ostringstream out;
  Rs274Printer printer(out);
  printer.emit(CanonCommand{1, WaitInput{}});
  printer.emit(CanonCommand{1, SetOutputBit{3, true, false}});
  EXPECT_EQ(out.str(), "SET_AUX_OUTPUT_BIT(3)\n");
}

// The daemon's task stops at the WaitInput, lets the machine wait, and hands the answer back
// before the next step(): #5399 holds it on the next line.
TEST(InterpIo, TheMachinesAnswerLandsInParameter5399) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string(
      "M66 P0 L3 Q1\n(debug,#5399)\nM66 P0 L3 Q1\n(debug,#5399)\nM66 E3\n(debug,#5399)\n"
      "M66 P1\n(debug,#5399)\nM2\n",
      "io.ngc"));
  Recorder r;
  const std::vector<double> answers{1.0, -1.0, 3.25};
  std::size_t next = 0;
  for (;;) {
    const std::size_t before = r.commands.size();
    const auto step = interp.step(r);
    ASSERT_NE(step, Interpreter::Step::error) << interp.error()->to_string();
    if (step == Interpreter::Step::end) break;
    bool waited = false;
    for (std::size_t i = before; i < r.commands.size(); ++i)
      waited = waited || std::holds_alternative<WaitInput>(r.commands[i].op);
    // The fourth wait gets no answer: #5399 reads as rs274 gives it (3.25 is not 0: 1).
    if (waited && next < answers.size()) interp.set_input_result(answers[next++]);
  }
  EXPECT_EQ(r.messages(),
            (std::vector<std::string>{"1.000000", "-1.000000", "3.250000", "1.000000"}));
}

TEST(InterpIo, WithoutAnAnswer5399ReadsAsRs274GivesIt) {
  const auto r =
      run("(debug,#5399)\nM66 P0\n(debug,#5399)\n#5399=5\nM66 E1\n(debug,#5399)\nM66 P1 L3 Q1\n"
          "(debug,#5399)\n#5399=0\nM66 P1 (debug,#5399)\n(debug,#5399)\nM2\n");
  EXPECT_EQ(r.messages(), (std::vector<std::string>{"0.000000", "0.000000", "5.000000", "1.000000",
                                                    "0.000000", "0.000000"}));
}

class InterpUserMCodes : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = std::filesystem::temp_directory_path() /
            ("cncd-user-m-" + std::to_string(::getpid()) + "-" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(root_);
    first_ = root_ / "first";
    second_ = root_ / "second";
    std::filesystem::create_directories(first_);
    std::filesystem::create_directories(second_);
    write(first_ / "M101", true);
    write(first_ / "M102", false);  // not executable
    std::filesystem::create_directories(first_ / "M103");
    ::chmod((first_ / "M103").c_str(), 0755);  // a directory, even one "executable"
    write(first_ / "m104", true);              // lower case: not M104
    write(first_ / "M105.sh", true);           // an extension: not M105
    write(second_ / "M101", true);             // the first directory wins
    write(second_ / "M102", true);             // found here, past the first's unusable one
    std::filesystem::create_symlink(first_ / "M101", second_ / "M106");
    options_.user_m_path = {first_, second_};
  }
  void TearDown() override { std::filesystem::remove_all(root_); }

  static void write(const std::filesystem::path& path, bool executable) {
    std::ofstream(path) << "#!/bin/sh\nexit 0\n";
    ::chmod(path.c_str(), executable ? 0755 : 0644);
  }

  std::filesystem::path root_;
  std::filesystem::path first_;
  std::filesystem::path second_;
  InterpOptions options_;
};

TEST_F(InterpUserMCodes, AFoundOneBecomesAUserMCodeWithItsPAndQ) {
  const auto r = run("M101 P1.5 Q-2\nM101\nM102 P3\nM106 Q4\nM2\n", options_);
  const auto codes = r.all<UserMCode>();
  ASSERT_EQ(codes.size(), 4u);
  EXPECT_EQ(codes[0].code, 101);
  EXPECT_EQ(codes[0].p, 1.5);
  EXPECT_EQ(codes[0].q, -2.0);
  EXPECT_EQ(codes[0].executable, (first_ / "M101").string());
  EXPECT_EQ(codes[1].p, -1.0);  // absent: LinuxCNC passes -1
  EXPECT_EQ(codes[1].q, -1.0);
  EXPECT_EQ(codes[2].executable, (second_ / "M102").string());
  EXPECT_EQ(codes[2].p, 3.0);
  EXPECT_EQ(codes[2].q, -1.0);
  EXPECT_EQ(codes[3].code, 106);  // a link to an executable file is one
  EXPECT_EQ(codes[3].executable, (second_ / "M106").string());
  EXPECT_EQ(format_rs274(CanonCommand{1, codes[0]}), "USER_M_CODE(101, 1.5000, -2.0000)");
}

TEST_F(InterpUserMCodes, OneFoundNowhereIsAnUnknownMCodeAtItsColumn) {
  EXPECT_EQ(error_of("G0 X1\nG0 X2 M103\nM2\n", options_), "2:7: Unknown m code used: M103");
  EXPECT_EQ(error_of("M104\nM2\n", options_), "1:1: Unknown m code used: M104");
  EXPECT_EQ(error_of("M105\nM2\n", options_), "1:1: Unknown m code used: M105");
  EXPECT_EQ(error_of("M199\nM2\n", options_), "1:1: Unknown m code used: M199");
  options_.user_m_path = {first_};
  EXPECT_EQ(error_of("M102\nM2\n", options_), "1:1: Unknown m code used: M102");
  EXPECT_EQ(error_of("M101\nM2\n"), "1:1: Unknown m code used: M101");  // no path at all
}

TEST_F(InterpUserMCodes, OnePerBlockAfterTheOverridesBeforeTheDwell) {
  EXPECT_EQ(error_of("M101 M102\nM2\n", options_), "1:6: Two m codes used from same modal group");
  const auto r = run("M101 M3 M8 M62 P2 G4\nM2\n", options_);
  std::vector<std::size_t> order;
  for (const auto& c : r.commands) {
    if (std::holds_alternative<SetOutputBit>(c.op) ||
        std::holds_alternative<StartSpindleClockwise>(c.op) ||
        std::holds_alternative<FloodOn>(c.op) || std::holds_alternative<UserMCode>(c.op) ||
        std::holds_alternative<Dwell>(c.op)) {
      order.push_back(c.op.index());
    }
  }
  const std::vector<std::size_t> expected{
      CanonOp(SetOutputBit{}).index(), CanonOp(StartSpindleClockwise{}).index(),
      CanonOp(FloodOn{}).index(), CanonOp(UserMCode{}).index(), CanonOp(Dwell{}).index()};
  EXPECT_EQ(order, expected);
  const auto codes = r.all<UserMCode>();
  ASSERT_EQ(codes.size(), 1u);
  EXPECT_EQ(codes[0].p, 2.0);  // P is shared with M62 and G4, as in LinuxCNC
}

}  // namespace
}  // namespace cncd::interp
