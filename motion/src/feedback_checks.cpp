#include "cncd/motion/feedback_checks.hpp"

#include <algorithm>
#include <cmath>

namespace cncd::motion {

FeedbackChecks::FeedbackChecks(const config::MachineConfig& config, int joint_count,
                               const JointDrivers& joint_driver, std::size_t history_depth)
    : config_(config),
      joint_count_(joint_count),
      joint_driver_(joint_driver),
      history_(joint_count, history_depth) {}

void FeedbackChecks::record(std::uint64_t cycle, const drivers::JointCommand* commands) noexcept {
  history_.record(cycle, commands);
  std::copy_n(commands, joint_count_, latest_.begin());
}

bool FeedbackChecks::check(const JointFeedbacks& feedback, std::uint64_t cycle,
                           std::uint32_t limits_ignored, RtEvent& fault) const noexcept {
  using Code = RtEvent::Code;
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const auto& fb = feedback[k];
    fault.joint = static_cast<std::int8_t>(j);
    if (!std::isfinite(fb.position)) {
      fault.code = Code::feedback_not_a_number;
      return false;
    }
    if (fb.fault || fb.stale) {
      fault.code = fb.fault ? Code::drive_fault : Code::feedback_stale;
      // The driver may know more (which drive, register or line; why a bus went quiet).
      fault.text[0] = '\0';
      if (joint_driver_[k] != nullptr)
        joint_driver_[k]->fault_reason(fault.text, sizeof fault.text);
      return false;
    }
    // A tripped limit switch stops everything, except while homing a joint configured to
    // ignore its limits (its home switch shares the limit input).
    if ((fb.min_limit || fb.max_limit) && (limits_ignored & (1u << j)) == 0) {
      fault.code = fb.min_limit ? Code::min_limit_switch : Code::max_limit_switch;
      return false;
    }
    // LinuxCNC's limit: FERROR at full speed, scaled down with speed, never below MIN_FERROR;
    // measured from the commands the feedback answers, at their speed.
    const drivers::JointCommand newer = answered_command(k, fb.command_cycle, cycle);
    // Feedback answering a command sent while the drives were off: the drive followed nothing.
    if (!newer.enable) continue;
    drivers::JointCommand older = newer;
    // An older command sent with the drives off still counts: it followed the drive.
    if (fb.previous_cycle != 0 && fb.previous_cycle < newer.cycle)
      older = answered_command(k, fb.previous_cycle, cycle);
    const auto& joint = config_.joints[k];
    const double speed = std::max(std::abs(older.velocity), std::abs(newer.velocity));
    const double limit =
        std::max(joint.min_ferror, joint.ferror * speed / std::max(joint.max_velocity, 1e-9));
    const double low = std::min(older.position, newer.position);
    const double high = std::max(older.position, newer.position);
    const double error = std::max({low - fb.position, fb.position - high, 0.0});
    if (error > limit) {
      const auto ago = [cycle](std::uint64_t then) {
        return cycle - 1 > then ? cycle - 1 - then : std::uint64_t{0};
      };
      fault.code = Code::following_error;
      fault.error = error;
      fault.limit = limit;
      fault.oldest_ago = ago(older.cycle);
      fault.newest_ago = ago(newer.cycle);
      return false;
    }
  }
  fault.joint = -1;
  return true;
}

drivers::JointCommand FeedbackChecks::answered_command(std::size_t k, std::uint64_t cycle,
                                                       std::uint64_t now) const noexcept {
  if (cycle != 0 && cycle < now) {
    if (const auto* command = history_.find(static_cast<int>(k), cycle)) return *command;
  }
  // The latest command (also when the driver names a cycle not written yet).
  return latest_[k];
}

}  // namespace cncd::motion
