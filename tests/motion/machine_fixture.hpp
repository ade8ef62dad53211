// A small fast mill built by hand, and a servo loop run in virtual time with its trajectory
// recorded, for the motion tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/sim_driver.hpp"
#include "cncd/motion/planner.hpp"
#include "cncd/motion/servo_loop.hpp"

namespace cncd::test {

// X/Y 200 mm/s and 2000 mm/s², Z 100 mm/s and 1000 mm/s², limits ±1000 (Z -500..500).
config::MachineConfig small_mill();

// A driver with no hardware behind it: configures, enables and disables at once, ignores its
// commands and leaves feedback as it is. Test drivers override what they act out.
class FakeDriver : public drivers::Driver {
 public:
  explicit FakeDriver(const char* name, std::uint32_t capabilities = 0)
      : name_(name), capabilities_(capabilities) {}
  std::string configure(const config::MachineConfig&, const std::vector<int>&) override {
    return "";
  }
  void enable() override {}
  void disable() override {}
  void write(const drivers::JointCommand*, int) noexcept override {}
  void read(drivers::JointFeedback*, int) noexcept override {}
  std::uint32_t capabilities() const noexcept override { return capabilities_; }
  const char* name() const noexcept override { return name_; }

 private:
  const char* name_;
  std::uint32_t capabilities_;
};

// Sits between the servo loop and a driver and keeps every period's motor commands.
class RecordingDriver final : public FakeDriver {
 public:
  RecordingDriver(drivers::Driver& inner, std::uint32_t capabilities)
      : FakeDriver("recording", capabilities), inner_(inner) {}
  void write(const drivers::JointCommand* commands, int count) noexcept override;
  void read(drivers::JointFeedback* feedback, int count) noexcept override {
    inner_.read(feedback, count);
  }
  void read_inputs(drivers::MachineInputs& inputs) noexcept override { inner_.read_inputs(inputs); }
  void write_io(const drivers::IoCommand& command) noexcept override {
    io_written_.push_back(command);  // test code: allocation is fine here
    inner_.write_io(command);
  }
  void read_io(drivers::IoFeedback& feedback) noexcept override { inner_.read_io(feedback); }
  // Every period's output commands.
  const std::vector<drivers::IoCommand>& io_written() const { return io_written_; }
  bool fault_reason(char* out, std::size_t size) const noexcept override {
    return inner_.fault_reason(out, size);
  }
  std::int64_t feedback_deadline_ns() const noexcept override {
    return inner_.feedback_deadline_ns();
  }
  const std::vector<motion::JointArray>& written() const { return written_; }
  // Whether the last write enabled the drives.
  bool enabled() const { return enabled_; }
  void clear() {
    written_.clear();
    io_written_.clear();
  }

 private:
  drivers::Driver& inner_;
  std::vector<motion::JointArray> written_;
  std::vector<drivers::IoCommand> io_written_;
  bool enabled_ = false;
};

class VirtualMachine {
 public:
  // `capabilities`: what the loop is told the driver can do (the sim's by default). `drive`:
  // the driver behind the recording one, already configured and outliving the machine (the
  // simulated driver by default).
  // `io_driver`: a driver of no joints for the spindle and signals, outliving the machine.
  explicit VirtualMachine(const config::MachineConfig& config,
                          std::uint32_t capabilities = drivers::kCapHomeSwitch |
                                                       drivers::kCapLimitSwitches |
                                                       drivers::kCapEstopInput,
                          drivers::Driver* drive = nullptr, drivers::Driver* io_driver = nullptr);
  // Machine on and homed.
  void ready();
  // Plans and queues through the look-ahead planner (which may hold the move back until the
  // next queue() or flush()); fails the test when the planner refuses.
  void queue(const motion::Move& move);
  // Releases the move the planner holds back. run_until_idle() does this first.
  void flush();
  // Runs cycles until the loop is idle with an empty queue, or `max_cycles`; records every
  // period's commanded pose. Returns the cycles run.
  int run_until_idle(int max_cycles = 2'000'000);
  void cycles(int n);
  void command(motion::Command::Kind kind, std::uint32_t mask = 0);
  // Any command, then one period.
  void send(const motion::Command& command);
  motion::Status status() const { return loop_->status(); }
  const std::vector<motion::AxisPose>& trajectory() const { return trajectory_; }
  // Every recorded period's motor commands (motor coordinates).
  const std::vector<motion::JointArray>& motor_trajectory() const { return recorder_->written(); }
  // Every recorded period's output commands, as the joint driver was handed them.
  const std::vector<drivers::IoCommand>& io_trajectory() const { return recorder_->io_written(); }
  void clear_trajectory() {
    trajectory_.clear();
    recorder_->clear();
  }
  bool drives_enabled() const { return recorder_->enabled(); }
  // The last motor command of joint `j`; with no lag, where the simulated motor stands.
  double motor_position(int j) const;
  drivers::SimDriver& sim() { return *sim_; }
  motion::ServoLoop& loop() { return *loop_; }
  const config::MachineConfig& config() const { return config_; }
  double period_s() const { return static_cast<double>(config_.servo_period_ns) * 1e-9; }

 private:
  config::MachineConfig config_;
  std::unique_ptr<drivers::SimDriver> sim_;
  std::unique_ptr<RecordingDriver> recorder_;
  std::unique_ptr<motion::ServoLoop> loop_;
  motion::Planner planner_;
  void pump();
  std::uint64_t pushed_ = 0;  // segments pushed to the ring since the loop started
  std::vector<motion::AxisPose> trajectory_;
};

// Largest ratio of any axis's speed and acceleration to its limit, by finite differences of
// the recorded periods (starting from rest at `start`).
struct Peaks {
  double velocity = 0;
  double acceleration = 0;
};
Peaks peaks(const VirtualMachine& m, const motion::AxisPose& start);
// The same for every joint against its [JOINT_n] limits, from the recorded motor commands.
Peaks joint_peaks(const VirtualMachine& m);
// Sends a jog command (of joint `index` when `joint`) and runs one period.
void send_jog(VirtualMachine& m, motion::Command::Kind kind, int index, double velocity,
              double distance = 0, bool joint = false);
// The servo loop's events since the last call, one line of words each.
std::string drain_events(VirtualMachine& m);
// Every joint within 100 % of its speed and acceleration limits over the recorded periods
// (and 1e-9 for what finite differences of positions in a double add); prints the peaks, as
// the figures the test stands for, and returns them.
Peaks expect_joints_within_limits(const VirtualMachine& m, const char* what);
// Every axis stayed within its velocity and acceleration limits (and 0.1 % for rounding) on
// the way from `start` through the recorded trajectory.
void expect_within_limits(const VirtualMachine& m, const motion::AxisPose& start);

motion::Move line_to(motion::Move::Kind kind, double x, double y, double z, double feed = 0);

// Makes `move` an arc in XY from (x, y), tangent there to `heading` (radians), of radius `r`,
// turning `sweep` radians counterclockwise (side 1) or clockwise (side -1); moves (x, y) and
// `heading` on to its end. The caller sets move.end.
void tangent_arc(motion::Move& move, double& x, double& y, double& heading, double r, double sweep,
                 double side);

}  // namespace cncd::test
