// M428 and M429 with the rotary axes anywhere, on the sim trunnion (sim_xyzac_trt.ini) in the
// plan simulation: the tool stays where it stands and the program goes on in the frame switched
// to, as LinuxCNC's switchkins remaps do (they read the position back after switching). Its
// own demo, xyzac_switchkins_test_3.ngc, says where: at C 90 with the joints at X 10 Y 0 Z 2,
// M428 shows the tip at X 0 Y -10 Z 2 in the part's frame, and M429 X 10 Y 0 again.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/motion/kinematics.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

struct Traced {
  pipeline::PlanSimResult result;
  std::vector<motion::AxisPose> joints;  // every servo period
};

class TcpSwitchPlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path(), "sim_xyzac_trt");
    auto loaded = config::load_machine_config(ini_);
    ASSERT_TRUE(loaded.ok());
    config_ = *loaded.config;
  }
  Traced simulate(const std::filesystem::path& program) {
    Traced run;
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(config_);
    options.start_machine = interp::Pose{};
    options.on_sample = [&](double, const motion::AxisPose& p, double) { run.joints.push_back(p); };
    run.result = pipeline::simulate_plan(config_, program.string(), options);
    return run;
  }
  // The largest step of any joint between two servo periods, in units of what its
  // MAX_VELOCITY allows in one: a jump at a switch would be far above 1.
  double largest_step(const Traced& run) const {
    double worst = 0;
    const double dt = static_cast<double>(config_.servo_period_ns) * 1e-9;
    const char* letters = "XYZAC";
    for (std::size_t k = 1; k < run.joints.size(); ++k) {
      for (int j = 0; j < 5; ++j) {
        const auto axis = static_cast<std::size_t>(j < 4 ? j : 5);
        const double vmax = config_.axis(letters[j]).max_velocity;
        worst =
            std::max(worst, std::abs(run.joints[k][axis] - run.joints[k - 1][axis]) / (vmax * dt));
      }
    }
    return worst;
  }
  TempDir dir_;
  std::filesystem::path ini_;
  config::MachineConfig config_;
};

TEST_F(TcpSwitchPlanTest, TheProgramGoesOnFromWhereTheToolStandsAtC90) {
  const auto program = dir_.write("switch.ngc",
                                  "G21 G90 G94\nM429\nG0 X0 Y0 Z0 A0 C0\nG0 C90 X10 Y0\n"
                                  "G1 F1000 Z2\nM428\nG1 Z0\nM429\nG1 Z2\nG0 X0 Y0 Z0 A0 C0\nM2\n");
  const Traced run = simulate(program);
  ASSERT_TRUE(run.result.complete())
      << (run.result.error ? run.result.error->to_string() : run.result.stopped->to_string());
  // From C 90 until the last traverse, X and Y never leave 10 and 0: Z goes up, down under
  // TCP and up again (each end reached within a servo period, whose sample may fall a little
  // after it: 1e-4 mm).
  std::size_t at_c90 = 0;
  while (at_c90 < run.joints.size() && run.joints[at_c90][5] < 90 - 1e-9)
    ++at_c90;
  ASSERT_LT(at_c90, run.joints.size());
  double lowest_after_2 = 1e9;
  bool reached_2 = false;
  std::size_t k = at_c90;
  for (; k < run.joints.size() && run.joints[k][5] > 90 - 1e-9; ++k) {
    EXPECT_NEAR(run.joints[k][0], 10, 1e-9) << "period " << k;
    EXPECT_NEAR(run.joints[k][1], 0, 1e-9) << "period " << k;
    if (run.joints[k][2] > 2 - 1e-4) reached_2 = true;
    if (reached_2) lowest_after_2 = std::min(lowest_after_2, run.joints[k][2]);
  }
  EXPECT_TRUE(reached_2);
  EXPECT_NEAR(lowest_after_2, 0, 1e-4);
  EXPECT_NEAR(run.joints[k - 1][2], 2, 1e-4);
  EXPECT_LE(largest_step(run), 1.0 + 1e-9);

  // The interpreter's view, as LinuxCNC's demo prints it: the tip at X 0 Y -10 under TCP.
  const auto check = run_command({CNCD_CHECK_BINARY, "--canon", "--ini", ini_.string(),
                                  "--state-dir", dir_.path().string(), program.string()});
  ASSERT_EQ(check.exit_status, 0) << check.err;
  EXPECT_NE(
      check.out.find("TCP_ON()\nSTRAIGHT_FEED(0.0000, -10.0000, 0.0000, 0.0000, 0.0000, 90.0000"),
      std::string::npos)
      << check.out;
  EXPECT_NE(
      check.out.find("TCP_OFF()\nSTRAIGHT_FEED(10.0000, 0.0000, 2.0000, 0.0000, 0.0000, 90.0000"),
      std::string::npos)
      << check.out;
}

// Tilted: at A -30 C 45 the tip moves along the part's Z under TCP (the joints along the
// tilted direction), then M429 and a move of X alone in joint space, with no jump at either
// switch.
TEST_F(TcpSwitchPlanTest, ATiltedTableSwitchesWithoutAJump) {
  const auto program = dir_.write(
      "tilted.ngc",
      "G21 G90 G94\nG0 X10 Y5 Z20 A-30 C45\nM428\nG91 G1 Z-5 F600\nG90 M429\nG1 X0\nM2\n");
  const Traced run = simulate(program);
  ASSERT_TRUE(run.result.complete())
      << (run.result.error ? run.result.error->to_string() : run.result.stopped->to_string());
  EXPECT_LE(largest_step(run), 1.0 + 1e-9);
  const auto kins = motion::make_kinematics(config_);
  motion::AxisPose start_joints{10, 5, 20, -30, 0, 45};
  motion::AxisPose start_tip{};
  kins->tcp_forward(start_joints, 0.0, start_tip);
  // Under TCP the tip keeps X and Y in the part's frame and goes 5 mm down its Z.
  double tip_x = 0, tip_y = 0, lowest = 1e9;
  for (const auto& j : run.joints) {
    if (std::abs(j[3] + 30) > 1e-9 || std::abs(j[5] - 45) > 1e-9) continue;
    motion::AxisPose tip{};
    kins->tcp_forward(j, 0.0, tip);
    if (j[0] != 0 && std::abs(j[0] - 10) < 1e-9 && std::abs(j[1] - 5) > 1e-9) {
      tip_x = std::max(tip_x, std::abs(tip[0] - start_tip[0]));
      tip_y = std::max(tip_y, std::abs(tip[1] - start_tip[1]));
    }
    lowest = std::min(lowest, tip[2]);
  }
  EXPECT_NEAR(lowest, start_tip[2] - 5, 1e-6);
  EXPECT_LE(tip_x, 1e-6);
  EXPECT_LE(tip_y, 1e-6);
  // Then X alone goes to 0 in joint space.
  EXPECT_NEAR(run.joints.back()[0], 0, 1e-9);
}

// LinuxCNC's own switchkins demos for this machine, where LinuxCNC's examples are installed.
TEST_F(TcpSwitchPlanTest, LinuxCncsSwitchkinsDemosRun) {
  const std::filesystem::path demos =
      "/usr/share/doc/linuxcnc/examples/sample-configs/sim/axis/vismach/5axis/"
      "table-rotary-tilting/demos";
  if (!std::filesystem::exists(demos)) GTEST_SKIP() << "LinuxCNC's examples are absent";
  for (const char* name : {"xyzac_switchkins_test_1.ngc", "xyzac_switchkins_test_2.ngc",
                           "xyzac_switchkins_test_3.ngc"}) {
    SCOPED_TRACE(name);
    const Traced run = simulate(demos / name);
    EXPECT_TRUE(run.result.complete())
        << (run.result.error ? run.result.error->to_string() : run.result.stopped->to_string());
    EXPECT_LE(largest_step(run), 1.0 + 1e-9);
  }
}

}  // namespace
}  // namespace cncd::test
