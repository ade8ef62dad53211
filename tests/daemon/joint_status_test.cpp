// status.get's per-joint entries on the real daemon: driver, drive enable, homed, switches and
// soft limits.
#include <fstream>
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr const char* kFlags[] = {
    "min_limit",         "max_limit",   "home_switch", "at_min_soft_limit",
    "at_max_soft_limit", "drive_fault", "stale",       "fault"};

TEST_F(MachineTest, JointsShowTheirDriveAndSoftLimits) {
  json s = status();
  ASSERT_TRUE(s["joints"].is_array()) << s.dump();
  ASSERT_EQ(s["joints"].size(), 3u);
  for (const auto& joint : s["joints"]) {
    EXPECT_EQ(joint["driver"], "sim");
    EXPECT_EQ(joint["enabled"], false);
    EXPECT_EQ(joint["homed"], false);
    for (const char* flag : kFlags)
      EXPECT_EQ(joint[flag], false) << flag << " in " << joint.dump();
  }
  // The field list picks the array alone.
  const json only = result_of(call("status.get", {{"fields", {"joints"}}}));
  EXPECT_EQ(only.size(), 1u);
  EXPECT_EQ(only["joints"].size(), 3u);

  ready_machine();
  s = status();
  for (const auto& joint : s["joints"]) {
    EXPECT_EQ(joint["enabled"], true) << joint.dump();
    EXPECT_EQ(joint["homed"], true) << joint.dump();
  }
  // Z (joint 2) up to its soft limit, [JOINT_2] MAX_LIMIT = 50.
  mdi("G53 G0 Z50");
  s = status();
  EXPECT_EQ(s["joints"][2]["at_max_soft_limit"], true) << s["joints"].dump();
  EXPECT_EQ(s["joints"][2]["at_min_soft_limit"], false);
  EXPECT_EQ(s["joints"][0]["at_max_soft_limit"], false);

  result_of(call("machine.off"));
  s = wait_until([](const json& st) { return st["state"] == "off"; });
  for (const auto& joint : s["joints"])
    EXPECT_EQ(joint["enabled"], false) << joint.dump();
}

// A joint that homes on a switch: the simulated switch sits at HOME_OFFSET, closed from there
// in the search direction, so joint 2 (at 0, searching upwards) starts on it.
TEST(JointStatusDaemon, HomeSwitchInputShows) {
  TempDir dir;
  const auto ini = copy_example_machine(dir.path());
  std::stringstream text;
  text << std::ifstream(ini).rdbuf();
  std::string config = text.str();
  const auto section = config.find("[JOINT_2]");
  ASSERT_NE(section, std::string::npos);
  const std::string search = "HOME_SEARCH_VEL = 0";
  const auto key = config.find(search, section);
  ASSERT_NE(key, std::string::npos);
  config.replace(key, search.size(), "HOME_SEARCH_VEL = 10");
  std::ofstream(ini) << config;

  DaemonProcess daemon;
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", ini.string()}), "");
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon.socket()), "");
  json s;
  for (int i = 0; i < 1000; ++i) {  // until the servo thread has read the switches once
    s = result_of(client.call("status.get", nullptr, 30000));
    if (s["rt"]["cycles"].get<std::uint64_t>() > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_EQ(s["joints"].size(), 3u) << s.dump();
  EXPECT_EQ(s["joints"][2]["home_switch"], true) << s["joints"].dump();
  EXPECT_EQ(s["joints"][0]["home_switch"], false);
  EXPECT_EQ(s["joints"][2]["min_limit"], false);
}

}  // namespace
}  // namespace cncd::test
