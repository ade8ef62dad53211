// The probe file of (PROBEOPEN name): a file name in the probe directory, a regular file that
// is no state file, opened without waiting; the lines each probe result writes there.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "probe_support.hpp"

namespace cncd::interp {
namespace {

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
  std::filesystem::create_directory(dir.path() / "sub");
  EXPECT_EQ(
      error_of("(PROBEOPEN sub)\nM2\n"),
      prog + ":1: Cannot open probe file " + (dir.path() / "sub").string() + ": Is a directory");
  EXPECT_EQ(error_of("(PROBEOPEN   )\nM2\n"),
            prog + ":1: PROBEOPEN without a file name: (PROBEOPEN results.txt)");
  // Only LinuxCNC's capitals open a file.
  EXPECT_EQ(error_of("(probeopen no/such/dir.txt)\nM2\n"), "no error");
}

// A name, not a path: whatever it says, the file is in the probe directory.
TEST(ProbeFile, ADirectoryInTheNameIsRefusedAtTheComment) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", "");
  for (const std::string name : {"/tmp/r.txt", "../r.txt", "sub/r.txt", "..", ".", "a/../r.txt"}) {
    dir.write("prog.ngc", "G21\n(PROBEOPEN " + name + ")\nM2\n");
    Interpreter interp;
    ASSERT_FALSE(interp.open(program));
    NullSink sink;
    const auto error = run_program(interp, sink);
    ASSERT_TRUE(error) << name;
    EXPECT_EQ(error->to_string(),
              program.string() + ":2: Cannot open probe file " + name +
                  ": give a file name without a directory; probe files go to the probe "
                  "directory ([CNCD] PROBE_DIR)");
  }
}

TEST(ProbeFile, MdiWithoutAProbeDirectoryNeedsTheSubroutinePath) {
  TempDir dir;
  {
    Interpreter interp;
    ASSERT_FALSE(interp.open_mdi("(PROBEOPEN r.txt)"));
    NullSink sink;
    const auto error = run_program(interp, sink);
    ASSERT_TRUE(error);
    EXPECT_EQ(error->to_string(),
              "MDI:1: Cannot open probe file r.txt: MDI has no program directory to put it in "
              "(set [RS274NGC] SUBROUTINE_PATH)");
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

// [CNCD] PROBE_DIR: the file goes there, not beside the program, and the directory is made
// (mode 0750) with the first result.
TEST(ProbeFile, TheFileGoesToTheProbeDirectory) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", "(PROBEOPEN r.txt)\nF1 G38.3 X1\nM2\n");
  InterpOptions options;
  options.probe_dir = dir.path() / "state" / "probe";
  std::filesystem::create_directory(dir.path() / "state");
  Interpreter interp(options);
  ASSERT_FALSE(interp.open(program));
  Recorder r;
  ASSERT_EQ(run_answering(interp, r, {pose(0.5, 0, 0)}), "");
  EXPECT_EQ(read(options.probe_dir / "r.txt").size(), 81U);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "r.txt"));
  struct stat st {};
  ASSERT_EQ(::stat(options.probe_dir.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0750U);
}

// A FIFO, a symlink or a device there could freeze the writer or send the results elsewhere.
TEST(ProbeFile, OnlyARegularFileIsWritten) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", "");
  ASSERT_EQ(::mkfifo((dir.path() / "fifo.txt").c_str(), 0600), 0);
  std::filesystem::create_symlink(dir.path() / "elsewhere.txt", dir.path() / "link.txt");
  std::filesystem::create_symlink("/dev/null", dir.path() / "null.txt");
  const std::pair<const char*, const char*> cases[] = {
      {"fifo.txt", "it is a FIFO (a probe file must be a regular file)"},
      {"link.txt", "it is a symbolic link (a probe file must be a regular file)"},
      {"null.txt", "it is a symbolic link (a probe file must be a regular file)"},
  };
  for (const auto& [name, why] : cases) {
    dir.write("prog.ngc", std::string("G21\n(PROBEOPEN ") + name + ")\nF1 G38.3 X1\nM2\n");
    Interpreter interp;
    ASSERT_FALSE(interp.open(program));
    Recorder r;
    EXPECT_EQ(run_answering(interp, r, {pose(1, 0, 0)}),
              program.string() + ":2: Cannot open probe file " + (dir.path() / name).string() +
                  ": " + why);
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "elsewhere.txt"));
}

// Made after the check of the comment, between two results: the write fails at the probe's
// line at once, rather than waiting for a reader that never comes.
TEST(ProbeFile, AFifoMadeAfterTheCommentIsRefusedWithoutWaiting) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", "(PROBEOPEN r.txt)\nF1\nG38.3 X1\nM2\n");
  Interpreter interp;
  ASSERT_FALSE(interp.open(program));
  Recorder r;
  ASSERT_EQ(interp.step(r), Interpreter::Step::block);  // the comment
  ASSERT_EQ(::mkfifo((dir.path() / "r.txt").c_str(), 0600), 0);
  EXPECT_EQ(run_answering(interp, r, {pose(1, 0, 0)}),
            program.string() + ":3: Cannot open probe file " + (dir.path() / "r.txt").string() +
                ": it is a FIFO (a probe file must be a regular file)");
}

// The parameter file, the tool table and the position file are never a probe file, even
// where the probe directory is theirs; nothing in them is lost.
TEST(ProbeFile, AStateFileIsNeverAProbeFile) {
  TempDir dir;
  const auto program = dir.write("prog.ngc", "");
  dir.write("m.var", "5161 1.5\n");
  dir.write("m.tbl", "T1 P1 Z1 ;one\n");
  dir.write("m.position", "0\n");
  InterpOptions options;
  options.probe_dir = dir.path();
  options.parameter_file = dir.path() / "m.var";
  options.tool_table = dir.path() / "m.tbl";
  options.state_files = {dir.path() / "m.position", dir.path() / "later.position"};
  for (const char* name : {"m.var", "m.tbl", "m.position", "later.position"}) {
    dir.write("prog.ngc", std::string("(PROBEOPEN ") + name + ")\nF1 G38.3 X1\nM2\n");
    Interpreter interp(options);
    ASSERT_FALSE(interp.open(program));
    Recorder r;
    EXPECT_EQ(run_answering(interp, r, {pose(1, 0, 0)}),
              program.string() + ":1: Cannot open probe file " + (dir.path() / name).string() +
                  ": it is the machine's state file " + (dir.path() / name).string() +
                  " (choose another name)");
  }
  EXPECT_EQ(read(dir.path() / "m.var"), "5161 1.5\n");
  EXPECT_EQ(read(dir.path() / "m.tbl"), "T1 P1 Z1 ;one\n");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "later.position"));
  // A hard link to one is the same file.
  std::filesystem::create_hard_link(dir.path() / "m.var", dir.path() / "alias.txt");
  dir.write("prog.ngc", "(PROBEOPEN alias.txt)\nF1 G38.3 X1\nM2\n");
  Interpreter interp(options);
  ASSERT_FALSE(interp.open(program));
  Recorder r;
  EXPECT_NE(run_answering(interp, r, {pose(1, 0, 0)}).find("is the machine's state file"),
            std::string::npos);
  EXPECT_EQ(read(dir.path() / "m.var"), "5161 1.5\n");
}

}  // namespace
}  // namespace cncd::interp
