// What the tests of the real daemon on real drivers share: status polling, a ready machine,
// and the example INIs adapted to a test's directory and drives.
#pragma once

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "client.hpp"
#include "daemon_process.hpp"
#include "test_util.hpp"

namespace cncd::test {

inline const std::string kExamples = std::string(CNCD_SOURCE_DIR) + "/config/examples/";

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

inline nlohmann::json result(const nlohmann::json& response) {
  EXPECT_TRUE(response.contains("result")) << response.dump();
  return response.value("result", nlohmann::json());
}

// Polls status.get every few milliseconds until `done(status)` or `seconds` pass (a test
// failure that shows the last status and the daemon's log); returns the last status.
template <typename Done>
nlohmann::json wait_for(daemon::Client& client, const DaemonProcess& daemon, int seconds,
                        Done done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
  nlohmann::json s;
  while (std::chrono::steady_clock::now() < deadline) {
    s = result(client.call("status.get"));
    if (done(s)) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ADD_FAILURE() << "condition not reached; last status: " << s.dump() << "\n" << daemon.log();
  return s;
}

// Machine reset, on and homed, and at rest.
inline void make_ready(daemon::Client& client, const DaemonProcess& daemon) {
  result(client.call("machine.reset"));
  result(client.call("machine.on"));
  result(client.call("machine.home"));
  wait_for(client, daemon, 60, [](const nlohmann::json& s) {
    for (const auto& h : s["homed"])
      if (!h.get<bool>()) return false;
    return s["motion"] == "idle";
  });
}

// cncd started on `ini` in `dir` with `client` connected, the machine made ready and
// `program` running. A failure is reported (ASSERT); the caller checks HasFatalFailure().
inline void run_on_new_daemon(DaemonProcess& daemon, daemon::Client& client, const TempDir& dir,
                              const std::string& ini, const std::string& program) {
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", ini}), "");
  ASSERT_EQ(client.connect(daemon.socket()), "");
  make_ready(client, daemon);
  result(client.call("program.open", {{"path", program}}));
  result(client.call("program.run"));
}

// The example INI with its files redirected into `dir`.
inline std::string adapt(const TempDir& dir, const std::string& name,
                         const std::vector<std::pair<std::string, std::string>>& replace) {
  std::string text = relocate_example_ini(slurp(kExamples + name));
  for (const auto& [from, to] : replace) {
    auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    for (; at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
  }
  dir.write("sim_mm.tbl", slurp(kExamples + "sim_mm.tbl"));
  dir.write("sim_mm.var", slurp(kExamples + "sim_mm.var"));
  return dir.write(name, text).string();
}

// The sim mill with its spindle on Modbus TCP at 127.0.0.1:`port` (bus 1, slave 3, the speed
// in tens of rpm, read every `update_ms`) with the spindle keys `extra`, ramping at 3000 rpm/s.
inline std::string modbus_spindle_ini(const TempDir& dir, int port, int update_ms,
                                      const std::string& extra) {
  return adapt(
      dir, "sim_mm.ini",
      {{"[SPINDLE_0]\nDRIVER = sim\n",
        "[MODBUS_1]\nTRANSPORT = tcp\nHOST = 127.0.0.1\nPORT = " + std::to_string(port) +
            "\nTIMEOUT_MS = 40\nUPDATE_PERIOD_MS = " + std::to_string(update_ms) +
            "\n\n[SPINDLE_0]\nDRIVER = modbus\nMODBUS = 1\nSLAVE = 3\nSPEED_SCALE = 0.1\n" + extra},
       {"ACCELERATION = 6000", "ACCELERATION = 3000"}});
}

}  // namespace cncd::test
