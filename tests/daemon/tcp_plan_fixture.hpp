// The trunnion example (config/examples/sim_xyzac_trt.ini) in the plan simulation (the
// daemon's pipeline, planner and servo loop in virtual time), for programs run with the table
// tilted under TCP: every servo period's joint commands and, through the forward kinematics,
// the tool tip in the part's frame; every programmed move as the planner plans it (under TCP
// the tip's path, in the part's frame) with the time it starts.
#pragma once

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/motion/kinematics.hpp"
#include "cncd/pipeline/machine.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {

struct TcpSample {
  double t = 0;
  motion::AxisPose joints{};  // the joints' axes, as status shows them
  motion::AxisPose tip{};     // the tool tip in the part's frame
  double revolutions = 0;     // the spindle's position
};

struct TcpRun {
  pipeline::PlanSimResult result;
  std::vector<TcpSample> samples;
  std::vector<motion::Segment> moves;  // programmed moves, as on_move gives them
  std::vector<double> move_start_s;
  std::vector<motion::Segment> segments;  // what the planner hands the servo loop (joints)
};

class TcpPlan : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path(), "sim_xyzac_trt");
    loaded_ = config::load_machine_config(ini_);
    ASSERT_TRUE(loaded_.ok());
    kins_ = motion::make_kinematics(*loaded_.config);
    ASSERT_TRUE(kins_->has_tcp());
  }

  // Simulates `text` (written as `name`) from the machine's zero.
  TcpRun simulate(const std::string& name, const std::string& text) {
    TcpRun run;
    pipeline::PlanSimOptions options;
    options.interp = pipeline::interpreter_options(*loaded_.config);
    options.start_machine = interp::Pose{};
    options.on_sample = [&](double t, const motion::AxisPose& joints, double revolutions) {
      TcpSample s;
      s.t = t;
      s.joints = joints;
      kins_->tcp_forward(joints, 0.0, s.tip);
      s.revolutions = revolutions;
      run.samples.push_back(s);
    };
    options.on_move = [&](const motion::Segment& m) { run.moves.push_back(m); };
    options.on_segment = [&](const motion::Segment& m) { run.segments.push_back(m); };
    run.result = pipeline::simulate_plan(*loaded_.config, dir_.write(name, text), options);
    EXPECT_TRUE(run.result.complete())
        << (run.result.error ? run.result.error->to_string() : run.result.stopped->to_string());
    run.move_start_s = run.result.move_start_s;
    return run;
  }

  // The joints that put the tool tip at part point (x, y, z) with A at `a` degrees, C at 0.
  motion::AxisPose joints_at(double x, double y, double z, double a) const {
    const motion::AxisPose part{x, y, z, a, 0, 0, 0, 0, 0};
    motion::AxisPose machine{};
    kins_->tcp_inverse(part, 0.0, machine);
    return machine;
  }

  static double xyz_distance(const motion::AxisPose& a, const motion::AxisPose& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
  }

  // The largest difference of any of X Y Z A C between two poses.
  static double pose_distance(const motion::AxisPose& a, const motion::AxisPose& b) {
    double d = 0;
    for (const int i : {0, 1, 2, 3, 5})
      d = std::max(d, std::abs(a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)]));
    return d;
  }

  TempDir dir_;
  std::filesystem::path ini_;
  config::LoadResult loaded_;
  std::unique_ptr<const motion::Kinematics> kins_;
};

}  // namespace cncd::test
