// Feedback checks, the servo loop's judge of what the drives report: a position that is not a
// number, a drive fault, stale feedback, a tripped limit switch and LinuxCNC's following error
// (FERROR at full speed, scaled down with speed, never below MIN_FERROR), measured against
// the commands the feedback answers, which it keeps for feedback that comes back late. It
// latches nothing: the servo loop decides what a fault stops.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"
#include "cncd/motion/command_history.hpp"
#include "cncd/motion/rt_event.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

class FeedbackChecks {
 public:
  using JointDrivers = std::array<drivers::Driver*, kJoints>;
  using JointFeedbacks = std::array<drivers::JointFeedback, kJoints>;

  // Non-RT. `joint_driver`: each joint's driver, asked for its own words about a fault (nullptr:
  // none); `history_depth`: the servo cycles of commands kept for late feedback.
  FeedbackChecks(const config::MachineConfig& config, int joint_count,
                 const JointDrivers& joint_driver, std::size_t history_depth);

  // RT: every joint's command written in servo cycle `cycle` (motor coordinates), every cycle
  // in turn.
  CNCD_RT void record(std::uint64_t cycle, const drivers::JointCommand* commands) noexcept;
  // RT: judges every joint's `feedback` (motor coordinates) read in servo cycle `cycle`, with
  // the drives enabled since the last cycle. Returns false with the first joint that fails in
  // `fault` (its code, joint and numbers; the driver's own words where it has some). The limit
  // switches of the joints in the mask `limits_ignored` (homing with HOME_IGNORE_LIMITS) do
  // not count.
  CNCD_RT bool check(const JointFeedbacks& feedback, std::uint64_t cycle,
                     std::uint32_t limits_ignored, RtEvent& fault) const noexcept;
  // RT: joint `k`'s command of `cycle` (motor coordinates) as feedback read in servo cycle
  // `now` names it: 0 or a cycle not written yet is the latest one written, one that fell out
  // of the history its oldest.
  CNCD_RT drivers::JointCommand answered_command(std::size_t k, std::uint64_t cycle,
                                                 std::uint64_t now) const noexcept;

 private:
  const config::MachineConfig& config_;
  int joint_count_;
  JointDrivers joint_driver_;
  CommandHistory history_;
  std::array<drivers::JointCommand, kJoints> latest_{};  // the commands recorded last
};

}  // namespace cncd::motion
