// What a program may make the daemon do to itself: a probe file that is a FIFO or a state
// file, a subroutine file that is a FIFO, a line of gigabytes, an arc of a hundred million
// turns. Each is refused or ends in an error at its line, while an estop is answered at once
// and SIGTERM still ends the daemon.
#include <sys/stat.h>

#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

class ProgramSafety : public MachineTest {
 protected:
  // The example machine with `lines` added to its [CNCD] section.
  void SetUp() override {}
  void start_with(const std::string& lines) {
    ini_ = copy_example_machine(dir_.path());
    std::string text = slurp(ini_);
    text.replace(text.find("[CNCD]\n"), 7, "[CNCD]\n" + lines);
    std::ofstream(ini_, std::ios::trunc) << text;
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  // The answer within `ms`, or null when none came (the daemon is stuck).
  nlohmann::json call_within(const std::string& method, int ms,
                             const nlohmann::json& params = nullptr) {
    try {
      return client_.call(method, params, ms);
    } catch (const std::runtime_error&) {
      return nullptr;
    }
  }
  // An estop answered within a generous 2 s, and SIGTERM ending the daemon within 10 s.
  void expect_estop_and_sigterm() {
    const auto estop = call_within("machine.estop", 2000);
    EXPECT_FALSE(estop.is_null()) << "machine.estop not answered within 2 s";
    EXPECT_EQ(daemon_.stop_within(10000), 0) << "the daemon did not end on SIGTERM";
  }
};

TEST_F(ProgramSafety, AFifoForAProbeFileEndsTheProgramAndNeverFreezesTheDaemon) {
  start_with("PROBE_DIR = " + dir_.path().string() + "\n");
  ready_machine();
  const auto program = dir_.write(
      "probe.ngc", "(PROBEOPEN results.txt)\nG21 G90\nG0 X10 Y20 Z0\nG38.3 Z-1 F50\nG4 P30\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  // Made after the check: nothing reads it. The run finds it at the comment.
  ASSERT_EQ(::mkfifo((dir_.path() / "results.txt").c_str(), 0600), 0);
  const auto run = call_within("program.run", 2000);
  ASSERT_FALSE(run.is_null()) << "program.run not answered within 2 s: the daemon is frozen";
  // Refused before any move: the run's own answer says why.
  EXPECT_TRUE(run.contains("error")) << run.dump();
  if (!run.contains("error")) {
    // Run anyway: its probe move takes 1.2 s, and then the file is opened.
    std::this_thread::sleep_for(std::chrono::seconds(3));
  }
  EXPECT_EQ(run.value("error", nlohmann::json::object()).value("message", ""),
            program.string() + ":1: Cannot open probe file " +
                (dir_.path() / "results.txt").string() +
                ": it is a FIFO (a probe file must be a regular file)");
  expect_estop_and_sigterm();
}

TEST_F(ProgramSafety, AProbeFileNamingTheParameterFileIsRefusedAndTheFileKept) {
  // The probe directory is the state directory: the names coincide.
  start_with("PROBE_DIR = " + dir_.path().string() + "\n");
  ready_machine();
  mdi("G10 L2 P1 X12.5");  // an offset the parameter file keeps
  const auto program = dir_.write(
      "probe.ngc", "(PROBEOPEN sim_mm.var)\nG21 G90\nG0 X10 Y20 Z0\nG38.3 Z-1 F50\nM2\n");
  const auto open = call("program.open", {{"path", program.string()}});
  ASSERT_TRUE(open.contains("error")) << open.dump();
  EXPECT_EQ(open["error"]["message"],
            program.string() + ":1: Cannot open probe file " +
                (dir_.path() / "sim_mm.var").string() + ": it is the machine's state file " +
                (dir_.path() / "sim_mm.var").string() + " (choose another name)");
  EXPECT_EQ(daemon_.stop_within(10000), 0);
  // The next start finds the parameter file whole, the offset in it.
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  ASSERT_EQ(client_.connect(daemon_.socket()), "");
  const auto offsets = result_of(call("offsets.get"));
  EXPECT_NE(offsets.dump().find("12.5"), std::string::npos) << offsets.dump();
}

// Opening a FIFO for reading waited for a writer on the opener's thread: that open never
// answered, nor did any later one, and shutdown waited for it for ever.
TEST_F(ProgramSafety, AFifoSubroutineFileIsRefusedAndLaterOpensAreAnswered) {
  start_with("");
  ASSERT_EQ(::mkfifo((dir_.path() / "far.ngc").c_str(), 0600), 0);
  const auto caller = dir_.write("caller.ngc", "G21\no<far> call\nM2\n");
  const auto open = call_within("program.open", 10000, {{"path", caller.string()}});
  ASSERT_FALSE(open.is_null()) << "program.open not answered";
  ASSERT_TRUE(open.contains("error")) << open.dump();
  EXPECT_EQ(open["error"]["message"], caller.string() + ":2: Cannot read subroutine file " +
                                          (dir_.path() / "far.ngc").string() +
                                          ": it is a FIFO, not a regular file");
  const auto plain = dir_.write("plain.ngc", "G21\nG0 X1\nM2\n");
  const auto next = call_within("program.open", 10000, {{"path", plain.string()}});
  ASSERT_FALSE(next.is_null()) << "a later program.open not answered";
  EXPECT_TRUE(next.contains("result")) << next.dump();
  EXPECT_EQ(daemon_.stop_within(10000), 0);
}

TEST_F(ProgramSafety, AGigabyteLineIsRefusedAtOpenNamingItsLine) {
  start_with("");
  const auto program = dir_.path() / "huge.ngc";
  { std::ofstream(program) << "G21\n"; }
  std::filesystem::resize_file(program, 3ULL << 30);  // sparse: no disk space taken
  const auto open = call_within("program.open", 20000, {{"path", program.string()}});
  ASSERT_FALSE(open.is_null()) << "program.open not answered";
  ASSERT_TRUE(open.contains("error")) << open.dump();
  EXPECT_EQ(open["error"]["message"],
            program.string() +
                ":2: Line is longer than 4096 characters (the longest line a program may have)");
  expect_estop_and_sigterm();
}

// Its extents were worked out a quarter turn at a time: 30 s of checking whatever the 5 s
// budget, and SIGTERM waited for it.
TEST_F(ProgramSafety, AnArcOfAHundredMillionTurnsIsCheckedQuickly) {
  start_with("");
  const auto program =
      dir_.write("turns.ngc", "G21 G90 F1000\nG0 X10 Y10 Z0\nG2 X10 Y10 I1 J0 P100000000\nM2\n");
  const auto open = call_within("program.open", 15000, {{"path", program.string()}});
  ASSERT_FALSE(open.is_null()) << "program.open not answered within 15 s";
  EXPECT_TRUE(open.contains("result")) << open.dump();
  // Beyond the X limit somewhere on the circle: refused, the same quickly.
  const auto wide =
      dir_.write("wide.ngc", "G21 G90 F1000\nG0 X10 Y10 Z0\nG2 X10 Y10 I-500 J0 P100000000\nM2\n");
  const auto refused = call_within("program.open", 15000, {{"path", wide.string()}});
  ASSERT_FALSE(refused.is_null()) << "program.open not answered within 15 s";
  EXPECT_TRUE(refused.contains("error")) << refused.dump();
  expect_estop_and_sigterm();
}

}  // namespace
}  // namespace cncd::test
