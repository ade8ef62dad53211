// The real cncd with its spindle on a loopback Modbus drive (VfdServer) that ramps at 3000
// rpm/s: a feed after M3 S1350 and then M4 S800 starts only once the drive has reported
// turning in reverse at 800 rpm, never on the at-speed bit it still showed for forward 1350.
#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "client.hpp"
#include "daemon_process.hpp"
#include "daemon_util.hpp"
#include "test_util.hpp"
#include "vfd_server.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

std::int64_t monotonic_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// A VFD of the generic profile without a position counter, ramping at 3000 rpm/s, its speed
// register in tens of rpm.
VfdMap ramping_vfd_map() {
  VfdMap map;
  map.units_per_rpm = 0.1;
  map.acceleration_rpm_s = 3000;
  return map;
}

void feeds_wait_for_the_reversal(const VfdMap& map, const std::string& position_keys) {
  VfdServer server(map, 3);
  ASSERT_EQ(server.start(), "");
  TempDir dir;
  const std::string ini = modbus_spindle_ini(dir, server.port(), 10, position_keys);
  const std::string program = dir.write("reverse.ngc",
                                        "G21 G90\nG0 X0 Y0 Z5\nM3 S1350\nG1 X10 F600\n"
                                        "M4 S800\nG1 X20 F600\nM5\nM2\n")
                                  .string();
  DaemonProcess daemon;
  daemon::Client client;
  run_on_new_daemon(daemon, client, dir, ini, program);
  if (::testing::Test::HasFatalFailure()) return;
  // The first status that shows the second feed under way, and when it was read: the feed
  // started before that.
  std::int64_t seen_moving_ns = 0;
  const json end = wait_for(client, daemon, 60, [&](const json& s) {
    if (seen_moving_ns == 0 && s["position"]["commanded"]["x"].get<double>() > 10 + 1e-6) {
      seen_moving_ns = monotonic_ns();
    }
    return s["exec"] == "idle" && s["program"]["result"] != "";
  });
  EXPECT_EQ(end["program"]["result"], "done") << end.dump() << daemon.log();
  ASSERT_NE(seen_moving_ns, 0);
  // The drive's answers: first at speed forward at 1350, then in reverse at 800, and the
  // latter before the second feed moved.
  const std::vector<VfdServer::AtSpeed> log = server.at_speed_log();
  std::string told;
  std::int64_t reverse_at_speed_ns = 0;
  for (const auto& entry : log) {
    told += std::to_string(entry.rpm) + " rpm at " + std::to_string(entry.time_ns) + " ns; ";
    if (reverse_at_speed_ns == 0 && std::abs(entry.rpm + 800) < 1e-6) {
      reverse_at_speed_ns = entry.time_ns;
    }
  }
  ASSERT_NE(reverse_at_speed_ns, 0) << told;
  EXPECT_LE(reverse_at_speed_ns, seen_moving_ns)
      << "the second feed moved " << (reverse_at_speed_ns - seen_moving_ns) / 1'000'000
      << " ms or more before the drive reported reverse 800 rpm at speed; " << told;
  EXPECT_EQ(daemon.stop(), 0) << daemon.log();
}

TEST(DaemonSpindle, AFeedAfterM4WaitsForAVfdAtSpeedInReverse) {
  feeds_wait_for_the_reversal(ramping_vfd_map(), "");
}

TEST(DaemonSpindle, AFeedAfterM4WaitsForAServoSpindleAtSpeedInReverse) {
  feeds_wait_for_the_reversal(servo_spindle_map(),
                              "POSITION_REGISTER = 10\nPOSITION_SCALE = 4096\n");
}

}  // namespace
}  // namespace cncd::test
