// The spindle, outputs and holds of a running program: tool changes the operator answers,
// user M codes run for the path, and what status shows of them.
#include <algorithm>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "task.hpp"

namespace cncd::daemon {
namespace {

const char* wait_kind_name(motion::WaitStatus::Kind kind) {
  static constexpr const char* kNames[] = {"",       "spindle_at_speed", "input", "tool_change",
                                           "user_m", "spindle_orient"};
  return enum_name(kind, kNames);
}

}  // namespace

WaitReport Task::wait_report(const motion::Status& s) const {
  WaitReport out;
  if (s.wait.kind == motion::WaitStatus::Kind::none || exec_ == ExecState::idle) return out;
  out.kind = wait_kind_name(s.wait.kind);
  out.since_s = s.sequence >= s.wait.since ? servo_seconds_since(s.wait.since) : 0.0;
  switch (s.wait.kind) {
    case motion::WaitStatus::Kind::spindle_at_speed:
      out.message = fmt::format("waiting for the spindle to reach {:.0f} rpm (now {:.0f} rpm)",
                                s.spindle.commanded_rpm, s.spindle.actual_rpm);
      break;
    case motion::WaitStatus::Kind::input:
      out.message = fmt::format("waiting for {} input {}", s.wait.digital ? "digital" : "analog",
                                s.wait.index);
      break;
    case motion::WaitStatus::Kind::spindle_orient:
      out.message = fmt::format("waiting for the spindle to orient to {:g} degrees (M19)",
                                s.spindle.orient_deg);
      break;
    case motion::WaitStatus::Kind::tool_change: {
      const auto* hold = runner_->feeder().hold(s.wait.hold_id);
      out.tool = hold != nullptr ? hold->tool : 0;
      std::string what;
      if (const auto entry = interp_->tool(out.tool); entry && !entry->comment.empty())
        what = " (" + entry->comment + ")";
      out.message = fmt::format("Insert T{}{} and press Enter", out.tool, what);
      break;
    }
    case motion::WaitStatus::Kind::user_m: {
      const auto* hold = runner_->feeder().hold(s.wait.hold_id);
      out.message = hold != nullptr ? fmt::format("running {}", hold->user.executable)
                                    : std::string("running a user M code");
      break;
    }
    case motion::WaitStatus::Kind::none:
      break;
  }
  return out;
}

void Task::tool_change_done(int tool) {
  const auto s = motion_.status();
  if (exec_ == ExecState::idle || s.wait.kind != motion::WaitStatus::Kind::tool_change)
    throw TaskError(TaskErrorKind::wrong_state,
                    fmt::format("no tool change is waiting: T{} is not asked for", tool));
  const auto* hold = runner_->feeder().hold(s.wait.hold_id);
  const int wanted = hold != nullptr ? hold->tool : 0;
  // An answer meant for another change (a second Enter, a confirmation sent before this
  // prompt was seen) must not let this one go on.
  if (tool != wanted) {
    throw TaskError(TaskErrorKind::bad_value,
                    fmt::format("the tool change waiting is for T{}, not T{}", wanted, tool));
  }
  events_.add("info", "tool", fmt::format("tool T{} put in", wanted));
  motion_.release_hold(s.wait.hold_id);
  runner_->feeder().erase_hold(s.wait.hold_id);
}

void Task::wait_done(const std::string& kind) {
  const auto s = motion_.status();
  const bool input = kind == "input";
  if (!input && kind != "spindle_at_speed") {
    throw TaskError(TaskErrorKind::bad_value,
                    fmt::format("wait kind '{}' is not input or spindle_at_speed", kind));
  }
  const auto wanted =
      input ? motion::WaitStatus::Kind::input : motion::WaitStatus::Kind::spindle_at_speed;
  if (exec_ == ExecState::idle || s.wait.kind != wanted)
    throw TaskError(TaskErrorKind::wrong_state, fmt::format("no {} wait is under way", kind));
  if (!input && (!s.spindle.enabled || s.spindle.actual_rpm <= 0)) {
    throw TaskError(TaskErrorKind::wrong_state,
                    "the spindle is not turning: it cannot be taken as at speed");
  }
  events_.add("warning", "program",
              input ? fmt::format("the wait for {} input {} was ended: #5399 = -1",
                                  s.wait.digital ? "digital" : "analog", s.wait.index)
                    : fmt::format("the wait for the spindle at speed was ended at {:.0f} rpm",
                                  s.spindle.actual_rpm));
  motion_.end_wait(wanted, s.wait.since);
}

// A run that ends before an M6 it read was carried out leaves in the spindle the tool that was
// there before that change, whatever the interpreter read after it; so does one that ends
// while it skips the lines before the one it runs from. A run that ended as written has made
// every change it read.
void Task::untake_tool_changes(bool ended_as_written) {
  const auto& holds = runner_->feeder().holds();
  const auto first = std::find_if(holds.begin(), holds.end(), [](const auto& h) {
    return h.second.kind == motion::IoAction::Hold::tool_change;
  });
  const int read = interp_->state().tool_in_spindle;
  const int in_spindle = ended_as_written       ? read
                         : first != holds.end() ? first->second.tool_before
                         : runner_->skipping()  ? tool_at_start_
                                                : read;
  runner_->feeder().erase_tool_changes();
  if (in_spindle == read) return;
  interp_->set_tool_in_spindle(in_spindle);
  events_.add("warning", "tool",
              fmt::format("the run ended before its tool change was made: T{} is in the spindle",
                          in_spindle));
}

bool Task::poll_holds(const motion::Status& s) {
  if (user_m_.running() || user_m_hold_ != 0) {
    const auto result = user_m_.poll();
    if (!result) return true;
    const auto* hold = runner_->feeder().hold(user_m_hold_);
    const int line = hold != nullptr ? hold->line : 0;
    const std::uint32_t id = user_m_hold_;
    user_m_hold_ = 0;
    runner_->feeder().erase_hold(id);
    if (!result->empty()) {
      motion_.abort();
      finish_program(
          "error", fmt::format("{}:{}: {} {}", program_path_, line, user_m_.executable(), *result));
      return false;
    }
    motion_.release_hold(id);
    return true;
  }
  if (s.wait.kind != motion::WaitStatus::Kind::user_m) return true;
  const auto* hold = runner_->feeder().hold(s.wait.hold_id);
  if (hold == nullptr) return true;
  const interp::UserMCode& user = hold->user;
  const std::string problem =
      user_m_.start(user.executable, user.p, user.q, config_.io.user_m_timeout_s);
  if (!problem.empty()) {
    motion_.abort();
    finish_program(
        "error", fmt::format("{}:{}: {} {}", program_path_, hold->line, user.executable, problem));
    return false;
  }
  spdlog::info("line {}: running {} {:f} {:f}", hold->line, user.executable, user.p, user.q);
  user_m_hold_ = s.wait.hold_id;
  return true;
}

}  // namespace cncd::daemon

namespace cncd::daemon {

void Task::poll_probe_file() {
  const auto error = probe_writer_->take_error();
  if (!error) return;
  if (exec_ == ExecState::idle) {
    events_.add("error", "program", *error);
    return;
  }
  motion_.abort();
  finish_program("error", *error);
}

}  // namespace cncd::daemon
