// One cncd per machine: a second daemon on the state directory of a running one refuses to
// start (exit 75, EX_TEMPFAIL) and names the first's pid, whatever socket it is given;
// `cncd --check-config` takes no lock and runs beside a daemon.
#include <gtest/gtest.h>

#include "daemon_process.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;

TEST(OneDaemon, ASecondDaemonOnTheSameStateDirectoryIsRefusedNamingTheFirst) {
  TempDir dir;
  const fs::path ini = copy_example_machine(dir.path());
  DaemonProcess first;
  ASSERT_EQ(first.start(dir.path(), {"--ini", ini.string()}), "");

  // Same INI and state directory, another socket (in another directory).
  TempDir elsewhere;
  DaemonProcess second;
  const std::string refused =
      second.start(elsewhere.path(), {"--ini", ini.string(), "--state-dir", dir.path().string()});
  EXPECT_NE(refused.find("cncd exited with status 75"), std::string::npos) << refused;
  EXPECT_NE(refused.find("the state directory '" + dir.path().string() +
                         "' is in use by cncd pid " + std::to_string(first.pid())),
            std::string::npos)
      << refused;
  EXPECT_FALSE(fs::exists(elsewhere.path() / "cncd.sock"));
  EXPECT_EQ(slurp(dir.path() / "cncd.lock"), std::to_string(first.pid()) + "\n");

  const auto checked = run_command(
      {CNCD_BINARY, "--check-config", ini.string(), "--state-dir", dir.path().string()});
  EXPECT_EQ(checked.exit_status, 0) << checked.err;

  // The first is untouched by all this, and once it has gone another may start there.
  EXPECT_EQ(first.stop(), 0) << first.log();
  DaemonProcess after;
  EXPECT_EQ(
      after.start(elsewhere.path(), {"--ini", ini.string(), "--state-dir", dir.path().string()}),
      "");
  EXPECT_EQ(after.stop(), 0);
}

}  // namespace
}  // namespace cncd::test
