// G38.2-G38.5 with a machine that answers (Interpreter::set_probe_result) and the probe file of
// (PROBEOPEN name). What rs274 can show (the canon, its checks, #5061-#5070 and the position
// without a machine) is in the goldens (tests/golden/probe_*, error_probe_*).
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

struct Recorder final : CanonSink {
  void emit(const CanonCommand& command) override {
    commands.push_back(command);
    if (std::holds_alternative<StraightProbe>(command.op)) probed = true;
  }
  template <class T>
  std::vector<T> all() const {
    std::vector<T> found;
    for (const auto& c : commands) {
      if (const auto* op = std::get_if<T>(&c.op)) found.push_back(*op);
    }
    return found;
  }
  std::vector<std::string> messages() const {
    std::vector<std::string> texts;
    for (const auto& m : all<Message>())
      texts.push_back(m.text);
    return texts;
  }
  std::vector<CanonCommand> commands;
  bool probed = false;  // a StraightProbe since the caller last looked
};

Pose pose(double x, double y, double z) {
  Pose p{};
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

// A scratch directory for one test.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("cncd-probe-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name) << text;
    return path_ / name;
  }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs a program whose machine answers each probe: the probe trips at `trips[n]` (machine
// coordinates) and stops 0.1 below it in Z. Returns the error text, "" at a clean end.
std::string run_answering(Interpreter& interp, Recorder& recorder, const std::vector<Pose>& trips) {
  std::size_t next = 0;
  for (;;) {
    const auto step = interp.step(recorder);
    if (step == Interpreter::Step::error) return interp.error()->to_string();
    if (step == Interpreter::Step::end) return "";
    if (recorder.probed) {
      recorder.probed = false;
      if (next < trips.size()) {
        const Pose trip = trips[next++];
        interp.set_probe_result(trip, true);
        Pose stop = trip;
        stop[2] -= 0.1;
        interp.set_machine_position(stop);
      }
    }
  }
}

TEST(Probe, EachCodeIsAProbeMoveOfItsKindBetweenProbeOnAndOff) {
  Interpreter interp;
  ASSERT_FALSE(
      interp.open_string("G21 F100\nG38.2 Z-1\nG38.3 X1\nG38.4 Y1\nG38.5 Z1\nM2\n", "p.ngc"));
  Recorder r;
  ASSERT_EQ(run_answering(interp, r, {}), "");
  const auto probes = r.all<StraightProbe>();
  ASSERT_EQ(probes.size(), 4U);
  EXPECT_EQ(probes[0].kind, ProbeKind::toward_or_error);
  EXPECT_EQ(probes[1].kind, ProbeKind::toward);
  EXPECT_EQ(probes[2].kind, ProbeKind::away_or_error);
  EXPECT_EQ(probes[3].kind, ProbeKind::away);
  EXPECT_EQ(probes[0].end[2], -1.0);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < r.commands.size(); ++i) {
    const auto& op = r.commands[i].op;
    if (std::holds_alternative<TurnProbeOn>(op) || std::holds_alternative<StraightProbe>(op) ||
        std::holds_alternative<TurnProbeOff>(op)) {
      order.push_back(op.index());
    }
  }
  ASSERT_EQ(order.size(), 12U);
  for (std::size_t i = 0; i < order.size(); i += 3) {
    EXPECT_EQ(order[i], CanonOp(TurnProbeOn{}).index());
    EXPECT_EQ(order[i + 1], CanonOp(StraightProbe{}).index());
    EXPECT_EQ(order[i + 2], CanonOp(TurnProbeOff{}).index());
  }
  EXPECT_EQ(r.commands.back().line, 6);
}

// The next line sees the machine's answer: #5061-#5069 in the program's coordinates and units,
// #5070 whether it tripped, and the position the machine stopped at.
TEST(Probe, TheNextLineSeesTheMachinesAnswer) {
  Interpreter interp;
  ASSERT_FALSE(
      interp.open_string("G21 F100\nG10 L2 P1 X10 Y20 Z0\nG0 X0 Y0 Z5\nG38.2 Z-10\n"
                         "(debug, #5061 #5062 #5063 #5070 #<_z>)\nG91 G1 X1\nG20 G90\nG38.3 X1\n"
                         "(debug, #5061 #5063 #5070)\nM2\n",
                         "p.ngc"));
  Recorder r;
  std::vector<CanonCommand> before_answer;
  int probes = 0;
  for (;;) {
    const auto step = interp.step(r);
    ASSERT_NE(step, Interpreter::Step::error) << interp.error()->to_string();
    if (step == Interpreter::Step::end) break;
    if (!r.probed) continue;
    r.probed = false;
    if (++probes == 1) {
      interp.set_probe_result(pose(11, 22, -3.5), true);
      interp.set_machine_position(pose(11, 22, -3.6));
    } else {
      interp.set_probe_result(pose(35.4, 22, -3.6), false);
      interp.set_machine_position(pose(35.4, 22, -3.6));
    }
  }
  const auto texts = r.messages();
  ASSERT_EQ(texts.size(), 2U);
  EXPECT_EQ(texts[0], " 1.000000 2.000000 -3.500000 1.000000 -3.600000");
  // Inches now: the machine's 35.4 mm, less the 10 mm origin, is 1 in; not tripped.
  EXPECT_EQ(texts[1], " 1.000000 -0.141732 0.000000");
  const auto feeds = r.all<StraightFeed>();
  ASSERT_EQ(feeds.size(), 1U);
  EXPECT_EQ(feeds[0].end, pose(2, 2, -3.6));  // from where the machine stopped
}

// Without an answer, step() reads on as LinuxCNC's standalone rs274: the programmed end in
// #5061-#5069 and 0 in #5070, whatever an earlier answer left there.
TEST(Probe, WithoutAnAnswerTheNextLineReadsAsRs274GivesIt) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string(
      "G21 F100\nG38.2 Z-4\n(debug, #5063 #5070)\nG38.2 X3\n(debug, #5061 #5063 #5070 #<_z>)\n"
      "M2\n",
      "p.ngc"));
  Recorder r;
  int probes = 0;
  for (;;) {
    const auto step = interp.step(r);
    ASSERT_NE(step, Interpreter::Step::error) << interp.error()->to_string();
    if (step == Interpreter::Step::end) break;
    if (r.probed && ++probes == 1) interp.set_probe_result(pose(0, 0, -2), true);
    r.probed = false;
  }
  const auto texts = r.messages();
  ASSERT_EQ(texts.size(), 2U);
  EXPECT_EQ(texts[0], " -2.000000 1.000000");
  EXPECT_EQ(texts[1], " 3.000000 -4.000000 0.000000 -4.000000");
}

TEST(Probe, InverseTimeIsRefused) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string("G21 F100\nG93 G38.2 Z-1 F2\nM2\n", "p.ngc"));
  NullSink sink;
  const auto error = run_program(interp, sink);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->to_string(), "p.ngc:2: Cannot probe in inverse time feed mode");
}

// A probe is a move: a loop of probes is no endless loop without motion.
TEST(Probe, ALoopOfProbesIsNoLoopWithoutMotion) {
  InterpOptions options;
  options.max_loops_without_motion = 10;
  Interpreter interp(options);
  ASSERT_FALSE(interp.open_string(
      "G21 F100\n#1=0\nO1 while [#1 LT 20]\nG38.3 Z[-1-#1]\n#1=[#1+1]\nO1 endwhile\nM2\n",
      "p.ngc"));
  Recorder r;
  EXPECT_EQ(run_answering(interp, r, {}), "");
  EXPECT_EQ(r.all<StraightProbe>().size(), 20U);
}

// --- the probe file -------------------------------------------------------------------------

constexpr const char* kFileProgram =
    "(PROBEOPEN results.txt)\nG21 F100\nG38.2 Z-1\nG38.2 Z-2 A10\n( PROBECLOSE)\nG38.2 Z-3\n"
    "M2\n";

TEST(ProbeFile, EachAnswerIsALineInTheFileNamedFromTheProgramsDirectory) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", kFileProgram);
  Interpreter interp;
  ASSERT_FALSE(interp.open(program));
  Recorder r;
  Pose second = pose(1.5, -2.25, -1.75);
  second[3] = 10;
  ASSERT_EQ(run_answering(interp, r, {pose(0, 0, -0.5), second, pose(0, 0, -2.5)}), "");
  // LinuxCNC's "%f %f %f %f %f %f %f %f %f": X Y Z A B C U V W, program coordinates.
  EXPECT_EQ(read(dir.path() / "results.txt"),
            "0.000000 0.000000 -0.500000 0.000000 0.000000 0.000000 0.000000 0.000000 "
            "0.000000\n"
            "1.500000 -2.250000 -1.750000 10.000000 0.000000 0.000000 0.000000 0.000000 "
            "0.000000\n");
}

// A run without a machine (cncd-check, the daemon's program check) answers no probe: the file
// of the last run stays as it was, and none is made.
TEST(ProbeFile, ARunWithoutAnswersLeavesTheFileAlone) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", kFileProgram);
  dir.write("results.txt", "last run\n");
  Interpreter interp;
  ASSERT_FALSE(interp.open(program));
  NullSink sink;
  EXPECT_FALSE(run_program(interp, sink));
  EXPECT_EQ(read(dir.path() / "results.txt"), "last run\n");
  std::filesystem::remove(dir.path() / "results.txt");
  ASSERT_FALSE(interp.open(program));
  EXPECT_FALSE(run_program(interp, sink));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "results.txt"));
}

TEST(ProbeFile, TheFirstAnswerEmptiesTheFile) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", "(PROBEOPEN r.txt)\nF1 G38.3 X1\nM2\n");
  dir.write("r.txt", "last run\nlast run\n");
  Interpreter interp;
  ASSERT_FALSE(interp.open(program));
  Recorder r;
  ASSERT_EQ(run_answering(interp, r, {pose(0.5, 0, 0)}), "");
  EXPECT_EQ(read(dir.path() / "r.txt"),
            "0.500000 0.000000 0.000000 0.000000 0.000000 0.000000 0.000000 0.000000 "
            "0.000000\n");
}

// Closed at PROBECLOSE, at the program's end and when another program opens: an answer after
// that writes nothing.
TEST(ProbeFile, ClosedAtTheEndAndWhenAnotherProgramOpens) {
  TempDir dir;
  const auto ends = dir.write("ends.ngc", "(PROBEOPEN a.txt)\nF1 G38.3 X1 M2\n");
  Interpreter interp;
  ASSERT_FALSE(interp.open(ends));
  Recorder r;
  while (interp.step(r) == Interpreter::Step::block) {
  }
  interp.set_probe_result(pose(1, 0, 0), true);  // after M2
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "a.txt"));

  const auto open = dir.write("open.ngc", "(PROBEOPEN b.txt)\nF1 G38.3 X1\nM2\n");
  ASSERT_FALSE(interp.open(open));
  ASSERT_EQ(interp.step(r), Interpreter::Step::block);
  ASSERT_EQ(interp.step(r), Interpreter::Step::block);
  interp.set_probe_result(pose(1, 0, 0), true);
  EXPECT_EQ(read(dir.path() / "b.txt").size(), 81U);
  ASSERT_FALSE(interp.open(ends));
  interp.set_probe_result(pose(2, 0, 0), true);
  EXPECT_EQ(read(dir.path() / "b.txt").size(), 81U);
}

TEST(ProbeFile, AFileThatCannotBeOpenedIsAnErrorAtItsComment) {
  TempDir dir;
  auto error_of = [&](const std::string& text) {
    const auto program = dir.write("prog.ngc", text);
    Interpreter interp;
    if (auto error = interp.open(program)) return error->to_string();
    NullSink sink;
    const auto error = run_program(interp, sink);
    return error ? error->to_string() : std::string("no error");
  };
  const std::string prog = (dir.path() / "prog.ngc").string();
  EXPECT_EQ(error_of("G21\n(PROBEOPEN no/such/dir.txt)\nM2\n"),
            prog + ":2: Cannot open probe file " + (dir.path() / "no/such/dir.txt").string() +
                ": No such file or directory");
  std::filesystem::create_directory(dir.path() / "sub");
  EXPECT_EQ(
      error_of("(PROBEOPEN sub)\nM2\n"),
      prog + ":1: Cannot open probe file " + (dir.path() / "sub").string() + ": Is a directory");
  EXPECT_EQ(error_of("(PROBEOPEN   )\nM2\n"),
            prog + ":1: PROBEOPEN without a file name: (PROBEOPEN results.txt)");
  // Only LinuxCNC's capitals open a file.
  EXPECT_EQ(error_of("(probeopen no/such/dir.txt)\nM2\n"), "no error");
}

// A result that cannot be written stops the program at the probe's line.
TEST(ProbeFile, AFailedWriteIsAnErrorAtTheProbesLine) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string("(PROBEOPEN /dev/full)\nF1\nG38.3 X1\nM2\n", "p.ngc"));
  Recorder r;
  const std::string error = run_answering(interp, r, {pose(1, 0, 0)});
  EXPECT_EQ(error, "p.ngc:3: Cannot write probe file /dev/full: No space left on device");
}

TEST(ProbeFile, MdiNeedsAFullNameOrTheSubroutinePath) {
  TempDir dir;
  {
    Interpreter interp;
    ASSERT_FALSE(interp.open_mdi("(PROBEOPEN r.txt)"));
    NullSink sink;
    const auto error = run_program(interp, sink);
    ASSERT_TRUE(error);
    EXPECT_EQ(error->to_string(),
              "MDI:1: Cannot open probe file r.txt: a relative name is taken from the program's "
              "directory, and MDI has none (give a full path, or set [RS274NGC] "
              "SUBROUTINE_PATH)");
  }
  InterpOptions options;
  options.subroutine_path = {dir.path()};
  Interpreter interp(options);
  Recorder r;
  // The file stays open from one MDI line to the next.
  for (const char* line : {"(PROBEOPEN r.txt)", "G21 F10", "G38.2 Z-1", "G38.2 Z-2"}) {
    ASSERT_FALSE(interp.open_mdi(line));
    ASSERT_EQ(run_answering(interp, r, {pose(0, 0, -0.25)}), "") << line;
  }
  EXPECT_EQ(read(dir.path() / "r.txt"),
            "0.000000 0.000000 -0.250000 0.000000 0.000000 0.000000 0.000000 0.000000 "
            "0.000000\n"
            "0.000000 0.000000 -0.250000 0.000000 0.000000 0.000000 0.000000 0.000000 "
            "0.000000\n");
}

}  // namespace
}  // namespace cncd::interp
