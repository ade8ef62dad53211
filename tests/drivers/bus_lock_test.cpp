// One cncd a Modbus bus: a daemon whose machine uses a bus another daemon drives refuses to
// start (exit 75) naming that daemon's pid, though their INI files and state directories
// differ. The bus is a loopback Modbus TCP server (a VFD).
#include <fstream>

#include <gtest/gtest.h>

#include "daemon_process.hpp"
#include "vfd_server.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;

// The example mill in `dir` with its spindle on the VFD at `port`, bus [MODBUS_1].
fs::path mill_on_vfd(const fs::path& dir, int port) {
  const fs::path ini = copy_example_machine(dir);
  std::string text = slurp(ini);
  const std::string from = "[SPINDLE_0]\nDRIVER = sim\n";
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos);
  if (at == std::string::npos) return ini;
  text.replace(at, from.size(),
               "[MODBUS_1]\nTRANSPORT = tcp\nHOST = 127.0.0.1\nPORT = " + std::to_string(port) +
                   "\n\n[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 1\nSLAVE = 3\n");
  std::ofstream(ini, std::ios::trunc) << text;
  return ini;
}

TEST(BusLock, TwoDaemonsOnOneModbusServerAreRefusedThoughTheirStateDirectoriesDiffer) {
  VfdServer server(VfdMap{}, 3);
  ASSERT_EQ(server.start(), "");
  TempDir first_dir;
  DaemonProcess first;
  ASSERT_EQ(first.start(first_dir.path(),
                        {"--ini", mill_on_vfd(first_dir.path(), server.port()).string()}),
            "");

  TempDir second_dir;
  DaemonProcess second;
  const std::string refused = second.start(
      second_dir.path(), {"--ini", mill_on_vfd(second_dir.path(), server.port()).string()});
  EXPECT_NE(refused.find("cncd exited with status 75"), std::string::npos) << refused;
  EXPECT_NE(refused.find("[MODBUS_1] (tcp 127.0.0.1:" + std::to_string(server.port()) +
                         ") is driven by cncd pid " + std::to_string(first.pid())),
            std::string::npos)
      << refused;

  // Once the first has gone, the bus is free (another process object: a second that started
  // against the lock must not be left running).
  EXPECT_EQ(first.stop(), 0) << first.log();
  DaemonProcess after;
  EXPECT_EQ(after.start(second_dir.path(), {"--ini", (second_dir.path() / "sim_mm.ini").string()}),
            "");
  EXPECT_EQ(after.stop(), 0) << after.log();
}

}  // namespace
}  // namespace cncd::test
