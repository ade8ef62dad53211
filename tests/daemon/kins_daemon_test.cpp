// The corexy example machine (config/examples/sim_corexy.ini) on the real daemon: status
// shows each joint's position beside the axes', the motors at X + Y and X - Y. The gantry
// example (sim_gantry.ini): both Y motors home to their own switches, then move as one.
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

class CorexyDaemonTest : public MachineTest {
 protected:
  std::string example() const override { return "sim_corexy"; }
};

TEST_F(CorexyDaemonTest, StatusShowsTheMotorsBesideTheAxes) {
  const nlohmann::json info = result_of(call("system.info"));
  EXPECT_EQ(info["machine"]["kinematics"], "corexykins") << info.dump();
  ready_machine();
  mdi("G0 X30 Y20 Z-5");
  const nlohmann::json s = wait_until([](const nlohmann::json& st) {
    return st["motion"] == "idle" && st["position"]["commanded"]["x"] == 30.0;
  });
  EXPECT_EQ(s["position"]["commanded"]["y"], 20.0) << s["position"].dump();
  EXPECT_EQ(s["position"]["actual"]["x"], 30.0) << s["position"].dump();
  EXPECT_EQ(s["position"]["actual"]["y"], 20.0);
  const auto& joints = s["joints"];
  ASSERT_EQ(joints.size(), 3u);
  EXPECT_EQ(joints[0]["commanded"], 50.0) << joints.dump();  // X + Y
  EXPECT_EQ(joints[1]["commanded"], 10.0);                   // X - Y
  EXPECT_EQ(joints[2]["commanded"], -5.0);                   // Z
  EXPECT_EQ(joints[0]["actual"], 50.0);
  EXPECT_EQ(joints[1]["actual"], 10.0);
}

class GantryDaemonTest : public MachineTest {
 protected:
  std::string example() const override { return "sim_gantry"; }
};

TEST_F(GantryDaemonTest, BothYMotorsHomeToTheirSwitchesThenMoveAsOne) {
  ready_machine();
  nlohmann::json s = status();
  ASSERT_EQ(s["joints"].size(), 4u) << s["joints"].dump();
  for (int j = 0; j < 4; ++j)
    EXPECT_EQ(s["joints"][j]["commanded"], 0.0) << j << ": " << s["joints"].dump();
  mdi("G0 X40 Y50 Z-5");
  s = wait_until([](const nlohmann::json& st) {
    return st["motion"] == "idle" && st["position"]["commanded"]["y"] == 50.0;
  });
  EXPECT_EQ(s["joints"][0]["commanded"], 40.0) << s["joints"].dump();
  EXPECT_EQ(s["joints"][1]["commanded"], 50.0);
  EXPECT_EQ(s["joints"][2]["commanded"], 50.0);
  EXPECT_EQ(s["joints"][3]["commanded"], -5.0);
  EXPECT_EQ(s["joints"][2]["actual"], 50.0);
}

}  // namespace
}  // namespace cncd::test
