#include "cncd/motion/servo_loop.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion {
namespace {

std::uint32_t home_switch_joints(const std::vector<DriverBinding>& drivers) {
  std::uint32_t mask = 0;
  for (const auto& binding : drivers) {
    if (!(binding.driver->capabilities() & drivers::kCapHomeSwitch)) continue;
    for (int j : binding.joints)
      mask |= 1u << j;
  }
  return mask;
}

// Enough cycles of commands to reach back as far as any driver's feedback may answer.
std::size_t history_depth(const std::vector<DriverBinding>& drivers, std::int64_t period_ns) {
  std::int64_t deadline_ns = 0;
  for (const auto& binding : drivers)
    deadline_ns = std::max(deadline_ns, binding.driver->feedback_deadline_ns());
  return CommandHistory::depth_for(deadline_ns, period_ns);
}

FeedbackChecks::JointDrivers joint_drivers(const std::vector<DriverBinding>& drivers) {
  FeedbackChecks::JointDrivers out{};
  for (const auto& binding : drivers) {
    for (int j : binding.joints) {
      if (j >= 0 && j < kJoints) out[static_cast<std::size_t>(j)] = binding.driver;
    }
  }
  return out;
}

std::uint32_t axes_present(const config::MachineConfig& config) {
  std::uint32_t mask = 0;
  for (int axis = 0; axis < kAxes; ++axis) {
    if (config.axes[static_cast<std::size_t>(axis)].present) mask |= 1u << axis;
  }
  return mask;
}

}  // namespace

ServoLoop::ServoLoop(const config::MachineConfig& config, std::vector<DriverBinding> drivers)
    : config_(config),
      drivers_(std::move(drivers)),
      period_s_(static_cast<double>(config.servo_period_ns) * 1e-9),
      joint_count_(static_cast<int>(std::min<std::size_t>(config.joints.size(), kJoints))),
      kins_(make_kinematics(config)),
      io_(config, period_s_),
      path_(config, period_s_),
      homing_(config, period_s_, home_switch_joints(drivers_)),
      jog_(config),
      joint_jog_(config, Jog::Space::joints),
      panel_(config.panel, period_s_, axes_present(config)),
      checks_(config, joint_count_, joint_drivers(drivers_),
              history_depth(drivers_, config.servo_period_ns)) {
  path_.set_gate(&io_);
  // The MPG's speed in velocity mode: its counts over about 50 ms.
  mpg_.window = std::clamp(static_cast<int>(std::lround(0.05 / period_s_)), 1, Mpg::kWindowMax);
  for (const auto& binding : drivers_) {
    for (int j : binding.joints) {
      if (j < 0 || j >= kJoints) continue;
      auto& driver = status_.joints[static_cast<std::size_t>(j)].driver;
      drivers::copy_text(driver, sizeof driver, binding.driver->name());
    }
  }
  status_.joint_count = joint_count_;
  published_.store(status_);
}

void ServoLoop::set_rt_flags(bool realtime, bool memory_locked) noexcept {
  status_.rt.realtime = realtime;
  status_.rt.memory_locked = memory_locked;
}

void ServoLoop::set_start_positions(const JointArray& joints) noexcept {
  start_positions_ = joints;
  has_start_positions_ = true;
  // Status shows them from the start, before the first cycle has read the drives.
  joints_.command = joints;
  joints_.feedback = joints;
  sync_axes_from_joints();
  publish();
}

void ServoLoop::adopt_start_positions() noexcept {
  has_start_positions_ = false;
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    joints_.motor_offset[k] = feedback_[k].position - start_positions_[k];
    joints_.feedback[k] = start_positions_[k];
    joints_.command[k] = start_positions_[k];
    last_motor_cmd_[k] = feedback_[k].position;
  }
  sync_axes_from_joints();
}

Status ServoLoop::status() const noexcept {
  Status out;
  static_cast<ServoStatus&>(out) = published_.load();
  if (out.fault.code != RtEvent::Code::none)
    format_event(out.fault, out.fault_reason, sizeof out.fault_reason);
  return out;
}

bool EventReader::pop(Event& out) noexcept {
  if (!ring_.pop(out.record)) return false;
  out.level = out.record.level;
  format_event(out.record, out.text, sizeof out.text);
  return true;
}

void ServoLoop::post(const RtEvent& event) noexcept {
  events_.push(event);  // a full ring drops the event rather than wait
}

void ServoLoop::warn(RtEvent::Code code, const char* words) noexcept {
  RtEvent event;
  event.code = code;
  event.level = EventLevel::warning;
  event.words = words;
  post(event);
}

void ServoLoop::latch_fault(RtEvent fault) noexcept {
  if (status_.fault.code == RtEvent::Code::none) {
    fault.level = EventLevel::fault;
    status_.fault = fault;
    post(fault);
  }
  stop_now(status_.machine == MachineState::estop ? MachineState::estop : MachineState::off);
}

void ServoLoop::latch_fault(RtEvent::Code code, int joint) noexcept {
  RtEvent fault;
  fault.code = code;
  fault.joint = static_cast<std::int8_t>(joint);
  latch_fault(fault);
}

void ServoLoop::stop_now(MachineState next) noexcept {
  path_.flush();
  homing_.stop_now();
  jog_.halt();
  joint_jog_.halt();
  // VOLATILE_HOME joints lose their home whenever the drives turn off.
  for (int j = 0; j < joint_count_; ++j) {
    if (config_.joints[static_cast<std::size_t>(j)].volatile_home)
      joints_.homed[static_cast<std::size_t>(j)] = false;
  }
  io_.stop_all();
  resume_pending_ = false;
  disarm_probe();
  status_.machine = next;
  status_.motion = MotionState::idle;
  status_.velocity = 0;
  status_.distance_to_go = 0;
  status_.axes_to_go = {};
}

bool ServoLoop::clear_into(MachineState from, MachineState to) noexcept {
  if (status_.machine != from) return false;
  status_.machine = to;
  status_.fault = {};
  status_.joint_fault = {};
  return true;
}

void ServoLoop::apply(const Command& command) noexcept {
  switch (command.kind) {
    case Command::Kind::estop:
      if (status_.machine != MachineState::estop) {
        stop_now(MachineState::estop);
        warn(RtEvent::Code::estop);
      }
      break;
    case Command::Kind::reset_estop:
      clear_into(MachineState::estop, MachineState::off);
      break;
    case Command::Kind::on:
      if (clear_into(MachineState::off, MachineState::on)) sync_axes_from_joints();
      break;
    case Command::Kind::off:
      if (status_.machine == MachineState::on) stop_now(MachineState::off);
      break;
    case Command::Kind::home:
      start_homing(command.joint_mask);
      break;
    case Command::Kind::abort:
      path_.abort();
      homing_.abort();
      jog_.stop_all();
      joint_jog_.stop_all();
      mpg_.drop = true;
      // The spindle, coolant and outputs stop at once, not when the path has come to rest.
      io_.stop_all();
      resume_pending_ = false;
      io_hold_pending_ = false;
      disarm_probe();
      break;
    case Command::Kind::pause:
      path_.pause();
      resume_pending_ = false;
      break;
    case Command::Kind::resume:
      // A spindle stopped by the pause or the door turns again first; the path (also one at
      // rest after M0, about to take new moves) waits for it.
      if (io_.resume_requested()) path_.pause();
      resume_pending_ = true;
      io_hold_pending_ = false;
      break;
    case Command::Kind::spindle_override:
      io_.set_override(command.velocity);
      break;
    case Command::Kind::release:
      io_.release(command.id);
      break;
    case Command::Kind::panel_lights:
      lights_asked_ = command.id;
      break;
    case Command::Kind::io_hold:
      io_hold_pending_ = true;
      io_hold_restore_ = command.id != 0;
      break;
    case Command::Kind::end_wait:
      io_.end_wait(static_cast<WaitStatus::Kind>(command.id), command.since);
      break;
    case Command::Kind::feed_override:
      // The controller clamps; a NaN would stall every later move.
      if (std::isfinite(command.velocity))
        status_.feed_override = std::clamp(command.velocity, 0.0, config_.max_feed_override);
      path_.set_overrides(status_.feed_override, status_.rapid_override);
      break;
    case Command::Kind::rapid_override:
      if (std::isfinite(command.velocity))
        status_.rapid_override = std::clamp(command.velocity, 0.0, 1.0);
      path_.set_overrides(status_.feed_override, status_.rapid_override);
      break;
    case Command::Kind::jog_start:
    case Command::Kind::jog_increment:
    case Command::Kind::jog_stop:
      apply_jog(command);
      break;
  }
}

void ServoLoop::start_homing(std::uint32_t mask) noexcept {
  if (status_.machine != MachineState::on) {
    warn(RtEvent::Code::home_ignored_not_on);
  } else if (path_.pending() || homing_.active() || jog_.active() || joint_jog_.active()) {
    warn(RtEvent::Code::home_ignored_moving);
  } else if (!homing_.start(mask, joints_)) {
    latch_fault(homing_.fault());
  } else {
    status_.motion = MotionState::homing;
    sync_axes_from_joints();
  }
}

void ServoLoop::advance_homing() noexcept {
  switch (homing_.update(joints_)) {
    case Homing::Result::failed:
      latch_fault(homing_.fault());
      return;
    case Homing::Result::aborted:
      warn(RtEvent::Code::homing_aborted);
      status_.motion = MotionState::idle;
      break;
    case Homing::Result::finished:
    case Homing::Result::idle:
      status_.motion = MotionState::idle;
      break;
    case Homing::Result::running:
      status_.motion = homing_.stopping() ? MotionState::stopping : MotionState::homing;
      break;
  }
  // Axes follow their joints while homing (a gantry's first joint leads its axis).
  sync_axes_from_joints();
}

int ServoLoop::joint_apart() const noexcept {
  JointArray placed = joints_.command;
  kins_->inverse(axis_pose_, kAllAxes, placed);
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    if (std::abs(joints_.command[k] - placed[k]) > 1e-6) return j;
  }
  return -1;
}

void ServoLoop::advance_path() noexcept {
  // Checked only from rest: while a move runs, the joints follow their axes.
  const int apart = path_.active() ? -1 : joint_apart();
  const PathExecutor::Result result = path_.advance(period_s_, axis_pose_, apart >= 0);
  status_.line = path_.line();
  status_.velocity = path_.velocity();
  status_.distance_to_go = path_.distance_to_go();
  const AxisPose* end = path_.segment_end();
  for (std::size_t i = 0; i < status_.axes_to_go.size(); ++i)
    status_.axes_to_go[i] = end != nullptr ? (*end)[i] - axis_pose_[i] : 0.0;
  status_.motion = path_.motion();
  if (result.fault == PathExecutor::Fault::joints_apart) {
    RtEvent fault;
    fault.code = RtEvent::Code::joints_apart;
    fault.joint = static_cast<std::int8_t>(apart);
    fault.axis = static_cast<std::int8_t>(kins_->axis_of_joint(apart));
    latch_fault(fault);
  } else if (result.fault == PathExecutor::Fault::off_path) {
    latch_fault(RtEvent::Code::off_path);
  }
  // Joints follow the path only while it moves: at rest they keep what homing left (a gantry
  // joint homed apart is caught, not jumped, when the next move starts).
  if (!result.moved) return;
  kins_->inverse(axis_pose_, kAllAxes, joints_.command);
}

void ServoLoop::advance_io() noexcept {
  if (resume_pending_ && io_.resume_ready()) {
    resume_pending_ = false;
    path_.resume();
  }
  if (status_.motion == MotionState::paused && !resume_pending_) io_.path_paused();
  if (io_hold_pending_ &&
      (status_.motion == MotionState::paused || status_.motion == MotionState::idle)) {
    io_.hold_at_rest(io_hold_restore_);
    io_hold_pending_ = false;
  }
  RtEvent error;
  if (io_.take_error(error)) {
    // The program stops there; the machine stays on.
    path_.flush();
    io_.stop_all();
    resume_pending_ = false;
    error.level = EventLevel::warning;
    status_.path_error = error;
    ++status_.path_errors;
    status_.motion = MotionState::idle;
    post(error);
  }
}

void ServoLoop::sync_axes_from_joints() noexcept {
  kins_->forward(joints_.command, axis_pose_);
}

void ServoLoop::update_stats(std::int64_t wake_error_ns) noexcept {
  histogram_.add(wake_error_ns);
  ++status_.rt.cycles;
  if (wake_error_ns > config_.servo_period_ns) ++status_.rt.overruns;
  // The percentiles walk the histogram: once a second or so is plenty.
  if ((status_.rt.cycles & 1023) == 1) {
    status_.rt.wake_error_p50_ns = histogram_.quantile_ns(0.5);
    status_.rt.wake_error_p99_ns = histogram_.quantile_ns(0.99);
    status_.rt.wake_error_p999_ns = histogram_.quantile_ns(0.999);
    histogram_.count_below(kWakeEdgesUs.data(), status_.rt.wake_error_below.data(),
                           kWakeEdgesUs.size());
    status_.rt.wake_error_count = histogram_.count();
    status_.rt.wake_error_sum_ns = histogram_.sum_ns();
  }
  std::uint64_t bus_errors = 0;
  for (const auto& binding : drivers_)
    bus_errors += binding.driver->exchange_errors();
  status_.rt.modbus_errors = bus_errors;
  status_.rt.wake_error_max_ns = histogram_.max_ns();
}

void ServoLoop::cycle(std::int64_t wake_error_ns) noexcept {
  ++cycle_;
  update_stats(wake_error_ns);
  Command command;
  // Feedback first: a command (homing) may redefine joint positions from it.
  read_drivers();
  if (has_start_positions_) adopt_start_positions();
  while (commands_.pop(command))
    apply(command);
  check_joints();
  check_spindle();
  if (config_.panel.present) advance_panel();

  if (status_.machine == MachineState::on) {
    if (homing_.active()) {
      advance_homing();
    } else if (jog_.active() || joint_jog_.active()) {
      advance_jog();
    } else {
      watch_probe();
      advance_path();
      follow_probe();
      io_.track_x(axis_pose_[0]);
      advance_io();
    }
  } else {
    // Drives off: the command follows the machine wherever it is pushed.
    joints_.command = joints_.feedback;
    sync_axes_from_joints();
  }
  if (config_.panel.present) settle_mpg();
  guard_set_points();
  write_drivers();
  publish();
}

}  // namespace cncd::motion
