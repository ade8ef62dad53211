// The machine's states (estop, off, on) and homing, as the operator commands them. A command
// answers with success only once the servo thread shows its effect: a drive that does not
// answer, a drive fault or an asserted estop input is the answer's error, not a later event.
#include <algorithm>
#include <thread>

#include "task.hpp"

namespace cncd::daemon {

namespace {
using Clock = std::chrono::steady_clock;

// The drives' feedback is judged from the first period after they were sent the enable; a few
// periods more cover a loaded machine's scheduling.
constexpr int kJudgedPeriods = 5;
constexpr auto kMinOnCheck = std::chrono::milliseconds(20);

// Why the machine is not in `wanted`: the latched fault, which names the joint, the drive and
// what went wrong, or the state it is in.
std::string why_not(const motion::Status& status, motion::MachineState wanted) {
  if (status.fault_reason[0] != '\0') return status.fault_reason;
  return std::string("the machine is ") + machine_state_name(status.machine) + ", not " +
         machine_state_name(wanted);
}
}  // namespace

void Task::wait_servo_periods(int periods) const {
  const std::uint64_t until = motion_.status().sequence + static_cast<std::uint64_t>(periods);
  // A stalled servo thread is the watchdog's to report; this wait stays short.
  const auto deadline = Clock::now() + std::chrono::seconds(1);
  while (motion_.status().sequence < until && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::microseconds(200));
}

void Task::estop() {
  motion_.estop();
  if (exec_ != ExecState::idle) finish_program("aborted", "estop");
  cancel_open("cancelled by machine.estop");
}

void Task::reset() {
  if (motion_.status().machine != motion::MachineState::estop) return;
  // The door in the estop chain holds the machine there while it is open.
  if (config_.panel.door_mode == config::PanelConfig::DoorMode::estop) refuse_if_door_open();
  motion_.reset_estop();
  // An estop input still asserted latches estop again in the next period.
  wait_servo_periods(kJudgedPeriods);
  const auto status = motion_.status();
  if (status.machine == motion::MachineState::estop) {
    throw TaskError(TaskErrorKind::fault,
                    "the machine stays in estop: " + why_not(status, motion::MachineState::off));
  }
}

std::chrono::steady_clock::duration Task::on_check_time() const {
  const auto periods =
      std::chrono::nanoseconds(config_.servo_period_ns * static_cast<std::int64_t>(kJudgedPeriods));
  return std::chrono::nanoseconds(motion_.feedback_deadline_ns()) +
         std::max<Clock::duration>(periods, kMinOnCheck);
}

bool Task::machine_on(std::uint64_t token) {
  const auto status = motion_.status();
  if (status.machine == motion::MachineState::estop) {
    throw TaskError(TaskErrorKind::wrong_state, "machine is in estop: reset it first");
  }
  if (status.machine == motion::MachineState::on && on_tokens_.empty()) return false;
  if (status.machine != motion::MachineState::on) {
    motion_.machine_on();
    on_check_until_ = Clock::now() + on_check_time();
  }
  if (token != 0) {
    // Answered by poll() once the drives have had the time to show a fault.
    on_tokens_.push_back(token);
    return true;
  }
  // Inside a batch: the answer is wanted now.
  while (Clock::now() < on_check_until_ && motion_.status().machine == motion::MachineState::on) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  const auto now_status = motion_.status();
  if (now_status.machine != motion::MachineState::on) {
    throw TaskError(TaskErrorKind::fault, "the machine did not come on: " +
                                              why_not(now_status, motion::MachineState::on));
  }
  return false;
}

void Task::confirm_machine_on(const motion::Status& status) {
  if (on_tokens_.empty()) return;
  if (status.machine == motion::MachineState::on && Clock::now() < on_check_until_) return;
  for (const auto token : on_tokens_) {
    if (token == kPanelToken) {
      if (status.machine != motion::MachineState::on) {
        const std::string before = events_.actor();
        events_.set_actor("panel");
        events_.add("warning", "command",
                    "MACHINE_ON: machine.on: the machine did not come on: " +
                        why_not(status, motion::MachineState::on));
        events_.set_actor(before);
      }
      continue;
    }
    if (status.machine == motion::MachineState::on) {
      answers_.post(token, CommandDone{});
    } else {
      answers_.post(token,
                    TaskError(TaskErrorKind::fault, "the machine did not come on: " +
                                                        why_not(status, motion::MachineState::on)));
    }
  }
  on_tokens_.clear();
}

void Task::machine_off() {
  if (exec_ != ExecState::idle) finish_program("aborted", "machine turned off");
  motion_.machine_off();
}

void Task::home(std::uint32_t joint_mask) {
  const auto status = motion_.status();
  if (status.machine != motion::MachineState::on) {
    throw TaskError(TaskErrorKind::wrong_state, "machine is not on");
  }
  if (exec_ != ExecState::idle) throw TaskError(TaskErrorKind::busy, "a program is running");
  // The servo thread would ignore the command (and say so only in the event log).
  if (status.motion == motion::MotionState::homing) {
    throw TaskError(TaskErrorKind::busy, "homing is already under way");
  }
  if (status.motion != motion::MotionState::idle || status.queued != 0) {
    throw TaskError(TaskErrorKind::busy, "the machine is moving");
  }
  motion_.home(joint_mask);
  // A homing configuration the servo thread refuses latches a fault and turns the machine off.
  const auto after = motion_.status();
  if (after.machine != motion::MachineState::on) {
    throw TaskError(TaskErrorKind::fault,
                    "homing did not start: " + why_not(after, motion::MachineState::on));
  }
}

void Task::drain_servo_events() {
  motion::Event event;
  while (motion_.poll_event(event)) {
    const char* level = event.level == motion::Event::Level::fault     ? "error"
                        : event.level == motion::Event::Level::warning ? "warning"
                                                                       : "info";
    events_.add(level, event.level == motion::Event::Level::fault ? "fault" : "servo", event.text,
                motion::event_code_name(event.record.code));
  }
  drivers::DriverNotice notice;
  for (auto* driver : drivers_) {
    while (driver->take_notice(notice)) {
      const bool warning = notice.level == drivers::DriverNotice::Level::warning;
      events_.add(warning ? "warning" : "info", "driver", notice.text);
    }
  }
}

}  // namespace cncd::daemon
