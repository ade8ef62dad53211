#include "machine_fixture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <gtest/gtest.h>

namespace cncd::test {

config::MachineConfig small_mill() {
  config::MachineConfig c;
  c.servo_period_ns = 1'000'000;
  c.coordinates = "XYZ";
  c.joint_count = 3;
  c.max_linear_velocity = 250;
  const double vmax[3] = {200, 200, 100};
  const double amax[3] = {2000, 2000, 1000};
  for (int i = 0; i < 3; ++i) {
    auto& axis = c.axes[static_cast<std::size_t>(i)];
    axis.present = true;
    axis.min_limit = i == 2 ? -500 : -1000;
    axis.max_limit = i == 2 ? 500 : 1000;
    axis.max_velocity = vmax[i];
    axis.max_acceleration = amax[i];
    config::JointConfig joint;
    joint.axis = "XYZ"[i];
    joint.min_limit = axis.min_limit;
    joint.max_limit = axis.max_limit;
    joint.max_velocity = vmax[i];
    joint.max_acceleration = amax[i];
    joint.ferror = 1;
    joint.min_ferror = 0.5;
    joint.home_sequence = 0;
    c.joints.push_back(joint);
  }
  return c;
}

void RecordingDriver::write(const drivers::JointCommand* commands, int count) noexcept {
  motion::JointArray positions{};
  for (int i = 0; i < count; ++i)
    positions[static_cast<std::size_t>(i)] = commands[i].position;
  written_.push_back(positions);  // test code: allocation is fine here
  enabled_ = count > 0 && commands[0].enable;
  inner_.write(commands, count);
}

VirtualMachine::VirtualMachine(const config::MachineConfig& config, std::uint32_t capabilities,
                               drivers::Driver* drive, drivers::Driver* io_driver)
    : config_(config), sim_(std::make_unique<drivers::SimDriver>()), planner_(config_) {
  std::vector<int> joints;
  for (std::size_t j = 0; j < config_.joints.size(); ++j)
    joints.push_back(static_cast<int>(j));
  EXPECT_EQ(sim_->configure(config_, joints), "");
  recorder_ = std::make_unique<RecordingDriver>(drive != nullptr ? *drive : *sim_, capabilities);
  std::vector<motion::DriverBinding> bindings{{recorder_.get(), joints}};
  if (io_driver != nullptr) bindings.push_back({io_driver, {}});
  loop_ = std::make_unique<motion::ServoLoop>(config_, std::move(bindings));
}

double VirtualMachine::motor_position(int j) const {
  const auto& written = recorder_->written();
  return written.empty() ? 0.0 : written.back()[static_cast<std::size_t>(j)];
}

void VirtualMachine::command(motion::Command::Kind kind, std::uint32_t mask) {
  ASSERT_TRUE(loop_->commands().push(motion::Command{kind, mask}));
  loop_->cycle(0);
}

void VirtualMachine::send(const motion::Command& command) {
  ASSERT_TRUE(loop_->commands().push(command));
  loop_->cycle(0);
}

void VirtualMachine::ready() {
  command(motion::Command::Kind::reset_estop);
  command(motion::Command::Kind::on);
  command(motion::Command::Kind::home, 0xFFFFFFFFu);
  run_until_idle();
  clear_trajectory();
  planner_.reset(status().commanded);
  pushed_ = status().segments_done;
}

void VirtualMachine::queue(const motion::Move& move) {
  // As MotionController does: with nothing held back and every queued segment done, the next
  // move starts where the machine stands (after an abort that is short of the last planned
  // end).
  const auto s = status();
  if (!planner_.holding() && s.segments_done == pushed_) planner_.reset(s.commanded);
  std::string error;
  ASSERT_TRUE(planner_.push(move, true, error)) << error;
  pump();
}

void VirtualMachine::flush() {
  planner_.flush();
  pump();
}

void VirtualMachine::pump() {
  auto& out = planner_.output();
  // A full ring takes the rest as the loop makes room (run_until_idle()).
  while (!out.empty() && loop_->segments().push(out.front())) {
    out.pop_front();
    ++pushed_;
  }
}

void VirtualMachine::cycles(int n) {
  for (int i = 0; i < n; ++i) {
    loop_->cycle(0);
    trajectory_.push_back(loop_->status().commanded);
  }
}

int VirtualMachine::run_until_idle(int max_cycles) {
  flush();
  for (int i = 0; i < max_cycles; ++i) {
    loop_->cycle(0);
    const auto s = loop_->status();
    trajectory_.push_back(s.commanded);
    pump();
    if (s.motion == motion::MotionState::idle && s.queued == 0 && planner_.output().empty())
      return i + 1;
  }
  ADD_FAILURE() << "motion did not finish within " << max_cycles << " cycles";
  return max_cycles;
}

namespace {

// Raises `p` to coordinate i's largest speed and acceleration over `points` (one a period of
// `dt` seconds), as ratios to its limits.
template <typename Points>
void add_peaks(Peaks& p, const Points& points, std::size_t i, double dt, double max_velocity,
               double max_acceleration) {
  for (std::size_t k = 2; k < points.size(); ++k) {
    const double v = (points[k][i] - points[k - 1][i]) / dt;
    const double v0 = (points[k - 1][i] - points[k - 2][i]) / dt;
    p.velocity = std::max(p.velocity, std::abs(v) / max_velocity);
    p.acceleration = std::max(p.acceleration, std::abs(v - v0) / dt / max_acceleration);
  }
}

}  // namespace

Peaks peaks(const VirtualMachine& m, const motion::AxisPose& start) {
  Peaks p;
  std::vector<motion::AxisPose> points{start, start};
  points.insert(points.end(), m.trajectory().begin(), m.trajectory().end());
  for (int axis = 0; axis < motion::kAxes; ++axis) {
    const auto& limits = m.config().axes[static_cast<std::size_t>(axis)];
    if (!limits.present) continue;
    add_peaks(p, points, static_cast<std::size_t>(axis), m.period_s(), limits.max_velocity,
              limits.max_acceleration);
  }
  return p;
}

void send_jog(VirtualMachine& m, motion::Command::Kind kind, int index, double velocity,
              double distance, bool joint) {
  motion::Command c;
  c.kind = kind;
  c.joint = joint;
  c.axis = index;
  c.velocity = velocity;
  c.distance = distance;
  ASSERT_TRUE(m.loop().commands().push(c));
  m.cycles(1);
}

std::string drain_events(VirtualMachine& m) {
  std::string text;
  motion::Event e;
  while (m.loop().events().pop(e))
    text += std::string(e.text) + "\n";
  return text;
}

Peaks joint_peaks(const VirtualMachine& m) {
  Peaks p;
  for (std::size_t j = 0; j < m.config().joints.size(); ++j) {
    const auto& joint = m.config().joints[j];
    add_peaks(p, m.motor_trajectory(), j, m.period_s(), joint.max_velocity, joint.max_acceleration);
  }
  return p;
}

Peaks expect_joints_within_limits(const VirtualMachine& m, const char* what) {
  constexpr double kRoundOff = 1e-9;
  const Peaks p = joint_peaks(m);
  std::printf("%s: peak joint velocity %.6f %%, acceleration %.6f %%\n", what, 100 * p.velocity,
              100 * p.acceleration);
  EXPECT_LE(p.velocity, 1.0 + kRoundOff) << what;
  EXPECT_LE(p.acceleration, 1.0 + kRoundOff) << what;
  return p;
}

void expect_within_limits(const VirtualMachine& m, const motion::AxisPose& start) {
  const Peaks p = peaks(m, start);
  EXPECT_LE(p.velocity, 1.001);
  EXPECT_LE(p.acceleration, 1.001);
}

motion::Move line_to(motion::Move::Kind kind, double x, double y, double z, double feed) {
  motion::Move m;
  m.kind = kind;
  m.end = {x, y, z, 0, 0, 0, 0, 0, 0};
  m.feed = feed;
  return m;
}

void tangent_arc(motion::Move& move, double& x, double& y, double& heading, double r, double sweep,
                 double side) {
  const double cx = x - side * r * std::sin(heading);
  const double cy = y + side * r * std::cos(heading);
  const double a1 = heading - side * std::numbers::pi / 2 + side * sweep;
  x = cx + r * std::cos(a1);
  y = cy + r * std::sin(a1);
  heading += side * sweep;
  move.kind = motion::Move::Kind::arc;
  move.center_first = cx;
  move.center_second = cy;
  move.turns = side > 0 ? 1 : -1;
}

}  // namespace cncd::test
