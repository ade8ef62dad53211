// The corexy example machine (config/examples/sim_corexy.ini) on the real daemon: status
// shows each joint's position beside the axes', the motors at X + Y and X - Y. The gantry
// example (sim_gantry.ini): both Y motors home to their own switches, then move as one.
#include <cstdio>

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

// Joint mode over the socket and through cncctl: before homing one Y motor jogs alone, Y then
// refuses to jog (its twin would jump), the motor jogs back, and once homed it refuses.
TEST_F(GantryDaemonTest, OneMotorJogsAloneBeforeHomingAndNotAfter) {
  result_of(call("machine.reset"));
  result_of(call("machine.on"));
  result_of(call("jog.start", {{"joint", 2}, {"velocity", 5}, {"heartbeat_s", 1}}));
  nlohmann::json s = status();
  EXPECT_EQ(s["manual_holder"]["joint"], 2) << s["manual_holder"].dump();
  EXPECT_TRUE(s["manual_holder"]["axis"].is_null());
  const auto beat = result_of(call("jog.heartbeat"));
  EXPECT_EQ(beat["joints"], nlohmann::json::array({2})) << beat.dump();
  result_of(call("jog.stop", {{"joint", 2}}));
  s = wait_until([](const nlohmann::json& st) { return st["motion"] == "idle"; });
  const double apart = s["joints"][2]["commanded"].get<double>();
  EXPECT_GT(apart, 0);
  EXPECT_EQ(s["joints"][1]["commanded"], 0.0);

  auto error = call("jog.increment", {{"axis", "Y"}, {"distance", 1}});
  ASSERT_TRUE(error.contains("error")) << error.dump();
  EXPECT_NE(error["error"]["message"].get<std::string>().find("stands apart"), std::string::npos)
      << error.dump();
  error = call("jog.start", {{"axis", "Y"}, {"joint", 1}, {"velocity", 1}});
  EXPECT_EQ(error["error"]["code"], -32602) << error.dump();
  error = call("jog.start", {{"joint", 4}, {"velocity", 1}});
  EXPECT_EQ(error["error"]["code"], -32602) << error.dump();
  error = call("jog.start", {{"velocity", 1}});
  EXPECT_EQ(error["error"]["code"], -32602) << error.dump();

  char back[40];
  std::snprintf(back, sizeof back, "%.17g", -apart);  // exactly back
  auto r = run_cncctl(daemon_.socket(), {"jog", "J2", "--increment", back});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("J1 0.0000  J2 0.0000"), std::string::npos) << r.out;
  r = run_cncctl(daemon_.socket(), {"jog", "Y", "--increment", "2"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  s = status();
  EXPECT_EQ(s["joints"][1]["commanded"], 2.0) << s["joints"].dump();
  EXPECT_EQ(s["joints"][2]["commanded"], 2.0);

  ready_machine();
  r = run_cncctl(daemon_.socket(), {"jog", "J2", "+1"});
  EXPECT_NE(r.exit_status, 0);
  EXPECT_NE(r.err.find("the joint is homed and moves with its axis"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace cncd::test
