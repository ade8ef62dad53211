// cncd-drive-sim's command line: the drive simulator the Modbus end-to-end tests run against.
#include <gtest/gtest.h>

#include "daemon_process.hpp"

namespace cncd::test {
namespace {

TEST(DriveSimCommand, RealTimePriorityOutsideItsRangeIsRefused) {
  for (const char* bad : {"100", "-1", "high", ""}) {
    const CommandResult r = run_command({DRIVE_SIM_BINARY, "--port", "0", "--rt-priority", bad});
    EXPECT_EQ(r.exit_status, 64) << bad;
    EXPECT_NE(r.err.find("--rt-priority wants 0 to 99, not '" + std::string(bad) + "'"),
              std::string::npos)
        << r.err;
  }
}

}  // namespace
}  // namespace cncd::test
