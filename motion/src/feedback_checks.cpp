#include "cncd/motion/feedback_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

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
                           std::uint32_t limits_ignored, Fault& fault) const noexcept {
  for (int j = 0; j < joint_count_; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const auto& fb = feedback[k];
    char* text = fault.text;
    constexpr std::size_t size = sizeof fault.text;
    if (!std::isfinite(fb.position)) {
      fault.joint = j;
      std::snprintf(text, size, "joint %d: feedback position is not a number", j);
      return false;
    }
    if (fb.fault || fb.stale) {
      fault.joint = j;
      // The driver may know more (which drive, register or line; why a bus went quiet).
      char detail[160] = {};
      if (joint_driver_[k] != nullptr) joint_driver_[k]->fault_reason(detail, sizeof detail);
      std::snprintf(text, size, "joint %d: %s%s%s", j,
                    fb.fault ? "drive fault" : "feedback is stale", detail[0] ? ": " : "", detail);
      return false;
    }
    // A tripped limit switch stops everything, except while homing a joint configured to
    // ignore its limits (its home switch shares the limit input).
    if ((fb.min_limit || fb.max_limit) && (limits_ignored & (1u << j)) == 0) {
      fault.joint = j;
      std::snprintf(text, size, "joint %d: %s limit switch tripped", j,
                    fb.min_limit ? "minimum" : "maximum");
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
      fault.joint = j;
      // Clamped: printing a huge number with %f would need a large buffer.
      const int n = std::snprintf(text, size, "joint %d: following error %.4f exceeds %.4f", j,
                                  std::min(error, 1e9), std::min(limit, 1e9));
      const auto ago = [cycle](std::uint64_t then) {
        return static_cast<unsigned long long>(cycle - 1 > then ? cycle - 1 - then : 0);
      };
      if (n > 0 && static_cast<std::size_t>(n) < size && ago(older.cycle) > 0) {
        const auto rest = size - static_cast<std::size_t>(n);
        if (older.cycle == newer.cycle) {
          std::snprintf(text + n, rest, " (against the command of %llu periods ago)",
                        ago(newer.cycle));
        } else {
          std::snprintf(text + n, rest, " (against the commands of %llu to %llu periods ago)",
                        ago(older.cycle), ago(newer.cycle));
        }
      }
      return false;
    }
  }
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
