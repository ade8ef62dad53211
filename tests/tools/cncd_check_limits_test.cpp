// cncd-check on programs made to exhaust it: a line of gigabytes (a sparse file), an arc of a
// hundred million turns, a FIFO in place of the program. Each ends soon with an error at its
// line or within its --max-seconds, never a crash or a hang. Each run is bounded by
// timeout(1): today's failure is a hang.
#include <sys/stat.h>

#include <chrono>
#include <fstream>

#include "cncd_check_fixture.hpp"

namespace cncd::test {
namespace {

class CncdCheckLimits : public CncdCheck {
 protected:
  CommandResult run_bounded(std::vector<std::string> args) {
    std::vector<std::string> argv{"/usr/bin/timeout", "-s", "KILL", "60", CNCD_CHECK_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    return run_command(argv);
  }
};

TEST_F(CncdCheckLimits, AGigabyteLineIsAnErrorAtItsLine) {
  const auto program = dir_.path() / "huge.ngc";
  { std::ofstream(program) << "G21\nG0 X1\n"; }
  std::filesystem::resize_file(program, 3ULL << 30);  // sparse: no disk space taken
  const auto r = run_bounded({program.string()});
  EXPECT_EQ(r.exit_status, 1) << r.err;
  EXPECT_NE(r.err.find(program.string() +
                       ":3: Line is longer than 4096 characters (the longest line a program may "
                       "have)"),
            std::string::npos)
      << r.err;
}

TEST_F(CncdCheckLimits, AFifoIsRefusedAtOnce) {
  const auto fifo = dir_.path() / "fifo.ngc";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto r = run_bounded({fifo.string()});
  EXPECT_EQ(r.exit_status, 1) << r.err;
  EXPECT_NE(r.err.find(fifo.string() + ": Unable to open file: it is a FIFO, not a regular file"),
            std::string::npos)
      << r.err;
}

// The check of its extents took 30 s whatever --max-seconds said; the plan simulation the
// same in the planner's soft-limit check.
TEST_F(CncdCheckLimits, AnArcOfAHundredMillionTurnsEndsWithinItsBudget) {
  const auto program =
      dir_.write("turns.ngc", "G21 G90 F1000\nG0 X10 Y10 Z0\nG2 X10 Y10 I1 J0 P100000000\nM2\n");
  for (const std::vector<std::string>& mode :
       {std::vector<std::string>{}, std::vector<std::string>{"--ini", ini_.string()},
        std::vector<std::string>{"--ini", ini_.string(), "--plan"}}) {
    std::vector<std::string> args = mode;
    args.insert(args.end(), {"--max-seconds", "2", program.string()});
    const auto start = std::chrono::steady_clock::now();
    const auto r = run_bounded(args);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_TRUE(r.exit_status == 0 || r.exit_status == 1) << r.exit_status << " " << r.err;
    // Generous for a loaded machine: the budget is 2 s.
    EXPECT_LT(seconds, 20) << mode.size() << " " << r.out << r.err;
  }
}

}  // namespace
}  // namespace cncd::test
