// The corexy example machine (config/examples/sim_corexy.ini) on the real daemon: status
// shows each joint's position beside the axes', the motors at X + Y and X - Y. The gantry
// example (sim_gantry.ini): both Y motors home to their own switches, then move as one. The
// trunnion (sim_xyzac_trt.ini): status shows the tool tip in the part's frame and the TCP
// state, the tip standing still while A turns under TCP.
#include <algorithm>
#include <cmath>
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
  // No TCP on this machine: neither the tip nor the state.
  EXPECT_TRUE(s["tool_tip"].is_null()) << s["tool_tip"].dump();
  EXPECT_TRUE(s["tcp"].is_null()) << s["tcp"].dump();
}

class TrtDaemonTest : public MachineTest {
 protected:
  std::string example() const override { return "sim_xyzac_trt"; }
};

// How far the tool tip of `s` (commanded or actual) stands from X Y Z `at`, in mm.
double tip_off(const nlohmann::json& s, const char* which, double x, double y, double z) {
  const auto& tip = s["tool_tip"][which];
  return std::hypot(tip["x"].get<double>() - x, tip["y"].get<double>() - y,
                    tip["z"].get<double>() - z);
}

TEST_F(TrtDaemonTest, StatusShowsTheToolTipAndTheTcpState) {
  const nlohmann::json info = result_of(call("system.info"));
  EXPECT_EQ(info["machine"]["kinematics"], "xyzac-trt-kins") << info.dump();
  ready_machine();
  nlohmann::json s = status();
  ASSERT_TRUE(s["tcp"].is_object()) << s.dump();
  EXPECT_EQ(s["tcp"], nlohmann::json({{"programmed", false}, {"motion", false}}));
  // Every rotary at 0: the part's frame is the machine's.
  EXPECT_EQ(s["tool_tip"]["commanded"], s["position"]["commanded"]) << s["tool_tip"].dump();
  EXPECT_EQ(s["tool_tip"]["actual"], s["position"]["actual"]);

  // The tip 40 mm out along X, 20 mm from the A axis (Y_OFFSET 20, Z_OFFSET 10): turning A
  // under TCP swings Y and Z round it while the tip stays put.
  start_program("tilt.ngc",
                "G21 G90 G94\nG0 X40 Y0 Z20 A0 C0\nM428\nG1 A-90 F1800\nM0\nG1 A0\nM429\n"
                "G0 X0\nM2\n");
  double drift_commanded = 0;
  double drift_actual = 0;
  double swing = 0;  // how far the joints' Y went from the tip's
  bool tcp_seen = false;
  s = wait_until([&](const nlohmann::json& st) {
    if (st["program"]["line"] == 4 && st["motion"] == "moving") {
      drift_commanded = std::max(drift_commanded, tip_off(st, "commanded", 40, 0, 20));
      drift_actual = std::max(drift_actual, tip_off(st, "actual", 40, 0, 20));
      swing = std::max(swing, std::abs(st["position"]["commanded"]["y"].get<double>()));
      tcp_seen = tcp_seen || st["tcp"]["motion"] == true;
    }
    return st["exec"] == "paused";
  });
  std::printf(
      "tool tip off X40 Y0 Z20 while A turns to -90 under TCP: commanded %.6f mm, "
      "actual %.6f mm; the joints' Y swung %.3f mm\n",
      drift_commanded, drift_actual, swing);
  EXPECT_TRUE(tcp_seen);
  EXPECT_LE(drift_commanded, 0.005);  // [TRAJ] TCP_TOLERANCE
  EXPECT_LE(drift_actual, 0.005);
  EXPECT_GT(swing, 10.0);
  // At the M0, A at -90: the joints stand far from the tip, which is where it was.
  EXPECT_EQ(s["tcp"], nlohmann::json({{"programmed", true}, {"motion", true}})) << s.dump();
  EXPECT_NEAR(s["position"]["commanded"]["a"].get<double>(), -90.0, 1e-9);
  EXPECT_NEAR(s["tool_tip"]["commanded"]["a"].get<double>(), -90.0, 1e-9);
  EXPECT_LE(tip_off(s, "commanded", 40, 0, 20), 1e-6) << s["tool_tip"].dump();
  EXPECT_LE(tip_off(s, "actual", 40, 0, 20), 1e-6);
  // The A axis at Y 20 Z 10: the tip, 20 mm before it and 10 mm above, is a quarter turn
  // round it from where the joints stand, 10 mm behind it and 20 mm above (Y 30, Z 30).
  EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 30.0, 1e-6) << s["position"].dump();
  EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), 30.0, 1e-6);
  auto r = cncctl({"status"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  const auto tip_line = r.out.substr(r.out.find("\ntip       ") + 1);
  EXPECT_NE(tip_line.find("X 40.0000"), std::string::npos) << r.out;
  EXPECT_LT(tip_line.find("X 40.0000"), tip_line.find("(tool tip, part's frame)")) << r.out;
  EXPECT_LT(tip_line.find("Z 20.0000"), tip_line.find("(tool tip, part's frame)")) << r.out;
  EXPECT_NE(r.out.find("\ntcp       motion on, next move on\n"), std::string::npos) << r.out;

  // The program levels A under TCP, switches it off and ends with a move without it.
  result_of(call("program.resume"));
  s = wait_until([](const nlohmann::json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["tcp"], nlohmann::json({{"programmed", false}, {"motion", false}}));
  EXPECT_EQ(s["tool_tip"]["commanded"], s["position"]["commanded"]);

  // By MDI: M428 is the interpreter's at once, the motion's from the next move on; the same
  // for M429.
  mdi("M428");
  EXPECT_EQ(status()["tcp"], nlohmann::json({{"programmed", true}, {"motion", false}}));
  mdi("G1 Z25 F600");
  EXPECT_EQ(status()["tcp"], nlohmann::json({{"programmed", true}, {"motion", true}}));
  mdi("M429");
  EXPECT_EQ(status()["tcp"], nlohmann::json({{"programmed", false}, {"motion", true}}));
  r = cncctl({"status"});
  EXPECT_NE(r.out.find("tcp       motion on, next move off"), std::string::npos) << r.out;
  mdi("G0 Z20");
  EXPECT_EQ(status()["tcp"], nlohmann::json({{"programmed", false}, {"motion", false}}));
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
