// Program files that could exhaust memory or wedge the reader: a line of gigabytes, a FIFO in
// place of the program or a subroutine file; and the subroutine index that lets a call jump to
// a definition far below without reading its way there.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "probe_support.hpp"

namespace cncd::interp {
namespace {

std::string run_file(const std::filesystem::path& program, InterpOptions options = {}) {
  Interpreter interp(options);
  NullSink sink;
  auto error = interp.open(program);
  if (!error) error = run_program(interp, sink);
  return error ? error->to_string() : "";
}

TEST(ProgramFiles, ALineLongerThanTheLimitIsAnErrorAtItsLine) {
  TempDir dir;
  const std::string longest(4096, ' ');
  const auto ok = dir.write("ok.ngc", "G21\n" + longest + "\r\nM2\n");
  EXPECT_EQ(run_file(ok), "");
  const auto bad = dir.write("bad.ngc", "G21\nG0 X1\n(" + std::string(4096, 'X') + ")\nM2\n");
  EXPECT_EQ(run_file(bad), bad.string() +
                               ":3: Line is longer than 4096 characters (the longest line a "
                               "program may have)");
  // In a subroutine file and in a sub read while seeking, the line is the file's own.
  const auto sub =
      dir.write("far.ngc", "o<far> sub\n" + std::string(5000, ';') + "\no<far> endsub\n");
  InterpOptions options;
  options.subroutine_path = {dir.path()};
  const auto caller = dir.write("call.ngc", "o<far> call\nM2\n");
  EXPECT_EQ(run_file(caller, options),
            sub.string() +
                ":2: Line is longer than 4096 characters (the longest line a program "
                "may have)");
  const auto seeking = dir.write("seek.ngc", "o<x> call\nM2\n" + std::string(9000, '(') + "\n");
  EXPECT_EQ(run_file(seeking).find(seeking.string() + ":3: Line is longer"), 0U);
}

// A sparse file of 3 GiB, one line of NUL bytes: refused at line 1 without reading it into
// memory (it grew past 1.4 GB and ended in bad_alloc).
TEST(ProgramFiles, AGigabyteLineIsRefusedWithoutReadingItIn) {
  TempDir dir;
  const auto program = dir.path() / "huge.ngc";
  { std::ofstream(program) << "G21\n"; }
  std::filesystem::resize_file(program, 3ULL << 30);
  EXPECT_EQ(run_file(program),
            program.string() +
                ":2: Line is longer than 4096 characters (the longest line a program may have)");
  SubroutineIndex index;
  const auto error = index_program(program, index);
  ASSERT_TRUE(error);
  EXPECT_EQ(error->to_string(), program.string() +
                                    ":2: Line is longer than 4096 characters (the "
                                    "longest line a program may have)");
}

// Opening a FIFO for reading waits for a writer: the program and its subroutine files must be
// regular files, refused at once otherwise.
TEST(ProgramFiles, AFifoIsRefusedAtOnce) {
  TempDir dir;
  const auto fifo = dir.path() / "fifo.ngc";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(run_file(fifo),
            fifo.string() + ": Unable to open file: it is a FIFO, not a regular file");
  ASSERT_EQ(::mkfifo((dir.path() / "sub.ngc").c_str(), 0600), 0);
  InterpOptions options;
  options.subroutine_path = {dir.path()};
  const auto caller = dir.write("call.ngc", "G21\no<sub> call\nM2\n");
  EXPECT_EQ(run_file(caller, options), caller.string() + ":2: Cannot read subroutine file " +
                                           (dir.path() / "sub.ngc").string() +
                                           ": it is a FIFO, not a regular file");
}

TEST(ProgramFiles, TheIndexHasEveryDefinitionAndTheLines) {
  TempDir dir;
  const auto program =
      dir.write("p.ngc", "o<a> call\nM2\no<a> sub\n  o<a> endsub\nO100 sub\nO100 endsub\no<a> sub");
  SubroutineIndex index;
  ASSERT_FALSE(index_program(program, index));
  EXPECT_EQ(index.lines, 7U);
  ASSERT_EQ(index.definitions.size(), 2U);
  ASSERT_EQ(index.definitions["a"].size(), 2U);
  EXPECT_EQ(index.definitions["a"][0].line, 3);
  EXPECT_EQ(index.definitions["a"][0].offset, 13);
  EXPECT_EQ(index.definitions["a"][1].line, 7);
  EXPECT_EQ(index.definitions["100"][0].line, 5);
}

// With the index, a call seeks to its definition: it does not read the lines between (here a
// second definition written over them after indexing is never seen), and a definition no longer
// where the index says is an error rather than a jump into the middle of something else.
TEST(ProgramFiles, ACallGoesStraightToTheIndexedDefinition) {
  TempDir dir;
  const std::string text =
      "G21\no<far> call\nM2\n(filler filler)\no<far> sub\nG0 X5\no<far> endsub\n%\n";
  const auto program = dir.write("p.ngc", text);
  auto index = std::make_shared<SubroutineIndex>();
  ASSERT_FALSE(index_program(program, *index));
  std::string changed = text;
  changed.replace(changed.find("(filler filler)"), 15, "o<far> sub\nG0 X");
  dir.write("p.ngc", changed);  // same length: the real definition stays where it was
  Interpreter interp;
  ASSERT_FALSE(interp.open(program, index));
  Recorder r;
  ASSERT_EQ(run_answering(interp, r, {}), "");
  ASSERT_EQ(r.all<StraightTraverse>().size(), 1U);
  EXPECT_EQ(r.all<StraightTraverse>()[0].end[0], 5);

  dir.write("p.ngc",
            "G21\no<far> call\nM2\n(a longer filler line)\no<far> sub\nG0 X5\no<far> endsub\n%\n");
  ASSERT_FALSE(interp.open(program, index));
  EXPECT_EQ(run_answering(interp, r, {}),
            program.string() + ":2: " + program.string() +
                " has changed since it was opened (o<far> sub is no longer at line 5): open it "
                "again");
}

// `text` as p.ngc in `dir`, run without and with its index: the outputs (canon, then the error)
// must be the same; returns the one with the index.
std::string run_both_ways(TempDir& dir, const std::string& text) {
  const auto program = dir.write("p.ngc", text);
  auto index = std::make_shared<SubroutineIndex>();
  EXPECT_FALSE(index_program(program, *index));
  std::string outputs[2];
  for (int indexed = 0; indexed < 2; ++indexed) {
    Interpreter interp;
    std::ostringstream out;
    Rs274Printer printer(out);
    auto error = interp.open(program, indexed ? index : nullptr);
    if (!error) error = run_program(interp, printer);
    outputs[indexed] = out.str() + (error ? error->to_string() : "");
  }
  EXPECT_EQ(outputs[0], outputs[1]);
  return outputs[1];
}

// A name that is a parameter or an expression is known only when the search passes it: the
// index keeps those lines, and a call evaluates them in file order, as a search that reads
// every line does (with the call's arguments in #1-#30), before a fixed definition further on.
TEST(ProgramFiles, TheIndexEvaluatesComputedNamesOnTheWay) {
  TempDir dir;
  const std::string found = run_both_ways(
      dir,
      "#<_n> = 100\no100 call [5]\nM2\no[#<_n> - 50] sub\no50 endsub\no#1 sub\no[#1 * 20] "
      "sub\nG0 X#1\no100 endsub\no100 sub\nG0 X99\no100 endsub\n");
  EXPECT_NE(found.find("STRAIGHT_TRAVERSE(5.0000,"), std::string::npos) << found;
  EXPECT_EQ(found.find("STRAIGHT_TRAVERSE(99.0000,"), std::string::npos) << found;
  const std::string failed =
      run_both_ways(dir, "o100 call\nM2\n\no[10 / 3] sub\no100 sub\no100 endsub\n");
  EXPECT_NE(failed.find("p.ngc:4:2: Non integer value for integer"), std::string::npos) << failed;
}

// The lines after a closing '%' are no part of the program: the index holds nothing of them,
// and knows whether a '%' closes the program that M2 ends.
TEST(ProgramFiles, TheIndexStopsAtTheClosingPercent) {
  TempDir dir;
  const std::string late =
      run_both_ways(dir, "\n%\no<late> call\nM2\n%\no<late> sub\nG0 X1\no<late> endsub\no#1 sub\n");
  EXPECT_NE(late.find("FINISH()\n"), std::string::npos) << late;
  EXPECT_NE(late.find("p.ngc:5: Failed to find sub 'Olate' before EOF"), std::string::npos) << late;
  const std::string early =
      run_both_ways(dir, "%\no<s> call\nM2\no<s> sub\nG0 X1\no<s> endsub\n%\n");
  EXPECT_NE(early.find("STRAIGHT_TRAVERSE(1.0000,"), std::string::npos) << early;
  EXPECT_EQ(early.find("percent sign missing"), std::string::npos) << early;
  const std::string open = run_both_ways(dir, "%\nG0 X1\nM2\n(no closing percent)\n");
  EXPECT_NE(open.find("COMMENT(\"interpreter: percent sign missing from end of file\")"),
            std::string::npos)
      << open;
}

}  // namespace
}  // namespace cncd::interp
