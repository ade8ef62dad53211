// The G43 tool length under TCP on the trunnion example (config/examples/sim_xyzac_trt.ini), in
// the plan simulation (the daemon's pipeline, planner and servo loop in virtual time) and the
// check program.open runs: the kinematics turn the tip of the tool whose length is in force,
// as LinuxCNC's do with their tool-offset pin netted to motion.tooloffset.z. Every servo
// period's joints, through the forward kinematics with that length, keep the tip on its point
// within the example's TCP_TOLERANCE; a length change with the table tilted, which would make
// the joints jump, is refused at its line.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "cncd/motion/kinematics.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "cncd/pipeline/program_check.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

constexpr double kTolerance = 0.005;  // the example's TCP_TOLERANCE
constexpr int kA = 3, kC = 5;

struct Held {
  double worst = 0;           // the tip's largest distance from the point, once there
  double lowest_a = 0;        // how far A tilted
  std::size_t held = 0;       // servo periods checked
  motion::AxisPose tilted{};  // the joints where A was lowest
};

class TcpToolPlan : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto ini = copy_example_machine(dir_.path(), "sim_xyzac_trt");
    auto loaded = config::load_machine_config(ini);
    ASSERT_TRUE(loaded.ok());
    config_ = *loaded.config;
    // T1 50 mm long, T2 30 mm.
    tools_ = dir_.write("tools.tbl", "T1 P1 Z50 D6 ;50 mm end mill\nT2 P2 Z30 D6 ;30 mm drill\n");
  }

  pipeline::PlanSimResult simulate(const std::string& text, std::vector<motion::AxisPose>& joints) {
    const auto program = dir_.write("tcp.ngc", text);
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(config_);
    options.interp.tool_table = tools_;
    options.start_machine = interp::Pose{};
    options.on_sample = [&](double, const motion::AxisPose& p, double) { joints.push_back(p); };
    return pipeline::simulate_plan(config_, program, options);
  }

  // From the first period a rotary leaves 0 (the program's first TCP move; the approach
  // before it turns none) to the end: the distance of the tip, through the forward kinematics
  // with `tool_length`, from `at` (the part's frame, the controlled point's coordinates).
  Held held_from(const std::vector<motion::AxisPose>& joints, const motion::AxisPose& at,
                 double tool_length) {
    const auto kins = motion::make_kinematics(config_);
    Held h;
    bool turning = false;
    for (const motion::AxisPose& j : joints) {
      turning = turning || j[kA] != 0 || j[kC] != 0;
      if (!turning) continue;
      motion::AxisPose part{};
      kins->tcp_forward(j, tool_length, part);
      h.worst = std::max(h.worst, std::hypot(part[0] - at[0], part[1] - at[1], part[2] - at[2]));
      if (j[kA] < h.lowest_a) {
        h.lowest_a = j[kA];
        h.tilted = j;
      }
      ++h.held;
    }
    return h;
  }

  TempDir dir_;
  config::MachineConfig config_;
  std::filesystem::path tools_;
};

std::string tilting(const char* tool) {
  return std::string("G21 G90 G94 G64\n") + tool +
         "\nG0 X30 Y40 Z20 A0 C0\nM428\nG1 A-90 F600\nG0 A0\nM429\nM2\n";
}

motion::AxisPose machine_at(double x, double y, double z) {
  return {x, y, z, 0, 0, 0, 0, 0, 0};
}

TEST_F(TcpToolPlan, G43KeepsThe50mmToolsTipOnItsPointWhileATilts) {
  std::vector<motion::AxisPose> joints;
  const auto r = simulate(tilting("G43 H1"), joints);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  // The tip at Z 20 in the program: the controlled point 50 mm above it.
  const Held h = held_from(joints, machine_at(30, 40, 70), 50);
  std::printf(
      "G43 H1 (50 mm), G1 A-90 under M428: the tip within %.6f mm of its point over %zu "
      "periods\n",
      h.worst, h.held);
  EXPECT_LE(h.worst, kTolerance);
  EXPECT_NEAR(h.lowest_a, -90, 1e-4);
  EXPECT_GT(h.held, 1000u);
  // The tip 20 mm behind the A axis (+Y; the axis at Y 20, Z 10) and 10 above it, turned -90
  // degrees: 10 mm behind it and 20 below, the controlled point 50 mm above that.
  EXPECT_NEAR(h.tilted[0], 30, 1e-4);
  EXPECT_NEAR(h.tilted[1], 30, 1e-4);
  EXPECT_NEAR(h.tilted[2], 40, 1e-4);
}

TEST_F(TcpToolPlan, TheSameProgramWithAnotherToolKeepsThatToolsTip) {
  std::vector<motion::AxisPose> joints;
  const auto r = simulate(tilting("G43 H2"), joints);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  const Held h = held_from(joints, machine_at(30, 40, 50), 30);
  std::printf("G43 H2 (30 mm), G1 A-90 under M428: the tip within %.6f mm of its point\n", h.worst);
  EXPECT_LE(h.worst, kTolerance);
  EXPECT_NEAR(h.lowest_a, -90, 1e-4);
  // The same tip, 20 mm less of tool above it.
  EXPECT_NEAR(h.tilted[1], 30, 1e-4);
  EXPECT_NEAR(h.tilted[2], 20, 1e-4);
  // The 50 mm tool's length with these joints would have put its tip 28 mm off.
  EXPECT_GT(held_from(joints, machine_at(30, 40, 50), 50).worst, 20);
}

TEST_F(TcpToolPlan, AG43ChangeBetweenTcpMovesAtA0TurnsTheNewToolsTip) {
  // C turns with the 30 mm tool; G43 H1 at A 0 moves no joint (the program's Z becomes the
  // 50 mm tool's tip, Z 0); A then tilts about that tip.
  std::vector<motion::AxisPose> joints;
  const auto r = simulate(
      "G21 G90 G94 G64\nG43 H2\nG0 X30 Y40 Z20 A0 C0\nM428\nG1 C90 F1800\nG43 H1\n"
      "G1 A-90 F600\nG0 A0 C0\nM429\nM2\n",
      joints);
  ASSERT_TRUE(r.complete()) << (r.error ? r.error->to_string() : r.stopped->to_string());
  const Held h = held_from(joints, machine_at(30, 40, 50), 50);
  std::printf("C 90 with the 30 mm tool, G43 H1, A -90: the 50 mm tool's tip within %.6f mm\n",
              h.worst);
  EXPECT_LE(h.worst, kTolerance);
  EXPECT_NEAR(h.lowest_a, -90, 1e-4);
  // C 90 takes the tip (30, 40, 0) to (-40, 30, 0); A -90 swings it about the A axis to
  // (-40, 10, 0), the controlled point 50 mm above.
  EXPECT_NEAR(h.tilted[0], -40, 1e-4);
  EXPECT_NEAR(h.tilted[1], 10, 1e-4);
  EXPECT_NEAR(h.tilted[2], 50, 1e-4);
}

TEST_F(TcpToolPlan, AToolLengthChangeWithTheTableTiltedIsRefusedAtItsLine) {
  std::vector<motion::AxisPose> joints;
  const auto r = simulate(
      "G21 G90 G94\nG43 H1\nG0 X30 Y40 Z20 A0 C0\nM428\nG1 A-30 F600\nG43 H2\nG1 X35\nM2\n",
      joints);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(r.error->line, 6);
  EXPECT_EQ(r.error->message,
            "the tool length offset changes from Z50.0000 to Z30.0000 under TCP (M428) with A at "
            "-30.0000: the joints would jump to put the new tool's tip on the part; change the "
            "tool length (G43, G43.1, G43.2, G49) with A at 0");
  // Nothing past A -30 ran: X never went on to 35.
  for (const motion::AxisPose& j : joints) {
    EXPECT_GE(j[kA], -30 - 1e-9);
    EXPECT_LE(j[0], 30 + 1e-9);
  }
  // G49 tilted is the same jump; G43 of the same length changes nothing.
  const auto g49 =
      simulate("G21 G90 G94\nG43 H1\nG0 X30 Y40 Z20 A0 C0\nM428\nG1 A-30 F600\nG49\nM2\n", joints);
  ASSERT_TRUE(g49.error);
  EXPECT_EQ(g49.error->line, 6);
  const auto same = simulate(
      "G21 G90 G94\nG43 H1\nG0 X30 Y40 Z20 A0 C0\nM428\nG1 A-30 F600\nG43.1 Z50\nG1 X35\nG0 "
      "X30 A0\nM429\nM2\n",
      joints);
  EXPECT_TRUE(same.complete()) << (same.error ? same.error->to_string() : "");
}

TEST_F(TcpToolPlan, AToolOffsetInXOrYIsRefusedUnderTcp) {
  // The kinematics turn the tip about the tool's length along Z alone.
  std::vector<motion::AxisPose> joints;
  const auto given =
      simulate("G21 G90 G94\nG0 X30 Y40 Z20 A0 C0\nM428\nG43.1 X2 Z50\nG1 A-30 F600\nM2\n", joints);
  ASSERT_TRUE(given.error);
  EXPECT_EQ(given.error->line, 4);
  EXPECT_EQ(given.error->message,
            "a tool length offset (G43, G43.1, G43.2) with a tool offset of X2.0000 Y0.0000: "
            "under TCP (M428) the tool is turned about its length along Z only; give the tool "
            "no X or Y offset");
  const auto switched = simulate(
      "G21 G90 G94\nG43.1 Y-1 Z50\nG0 X30 Y40 Z20 A0 C0\nM428\nG1 A-30 F600\nM2\n", joints);
  ASSERT_TRUE(switched.error);
  EXPECT_EQ(switched.error->line, 4);
  EXPECT_EQ(switched.error->message.rfind("M428 with a tool offset of X0.0000 Y-1.0000: ", 0), 0u)
      << switched.error->message;
}

TEST_F(TcpToolPlan, TheJointLimitCheckUsesTheLengthInForce) {
  // The tip at Y -50, Z 0 tilted to A -90: the Z joint at 80 + the tool's length, past its 120
  // with the 50 mm tool, within it with the 30 mm one. program.open's check sees it.
  const auto check = [&](const char* tool) {
    const auto program = dir_.write(
        "limits.ngc", std::string("G21 G90 G94\n") + tool +
                          "\nG0 X0 Y-50 Z0 A0 C0\nM428\nG1 A-90 F600\nG0 A0\nM429\nM2\n");
    pipeline::CheckOptions options;
    options.interp = pipeline::interpreter_options(config_);
    options.interp.tool_table = tools_;
    options.machine = &config_;
    options.start_machine = interp::Pose{};
    return pipeline::check_program(program, options);
  };
  const auto longer = check("G43 H1");
  // The tilt and the way back (the same swing) at their lines.
  ASSERT_EQ(longer.problems.size(), 2u);
  EXPECT_EQ(longer.problems[1].line, 6);
  EXPECT_EQ(longer.problems[1].message.rfind("rapid move: the move takes joint 2 (Z) to ", 0), 0u)
      << longer.problems[1].message;
  EXPECT_EQ(longer.problems[0].line, 5);
  const std::string& message = longer.problems[0].message;
  EXPECT_EQ(message.rfind("feed move: the move takes joint 2 (Z) to ", 0), 0u) << message;
  EXPECT_NE(message.find("outside its soft limits [-120.0000, 120.0000]"), std::string::npos)
      << message;
  const auto shorter = check("G43 H2");
  EXPECT_TRUE(shorter.ok()) << (shorter.problems.empty() ? "" : shorter.problems[0].message);
}

}  // namespace
}  // namespace cncd::test
