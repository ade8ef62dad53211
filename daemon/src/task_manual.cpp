// The operator's manual controls: jogs and the overrides.
#include <bit>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "task.hpp"

namespace cncd::daemon {

namespace {

TaskError jog_refused(const std::string& reason) {
  const bool busy = reason == "the machine is moving" || reason == "the machine is jogging" ||
                    reason.find("MPG") != std::string::npos;
  return TaskError(busy ? TaskErrorKind::busy : TaskErrorKind::wrong_state, reason);
}

// "1.5 (150 %)"
std::string ratio_text(double ratio) {
  return fmt::format("{:g} ({:g} %)", ratio, ratio * 100.0);
}

}  // namespace

std::optional<ManualHolder> Task::manual_holder(const motion::Status& status) const {
  if (status.panel.mpg_jogging) return ManualHolder{"the panel's MPG", true, status.panel.mpg_axis};
  // A client's jog holds from its start, before the servo thread's status shows it moving.
  const bool client_starting =
      client_jog_axes_ != 0 && status.sequence < client_jog_cycle_ + kJogSeenCycles;
  if (status.motion != motion::MotionState::jogging && !client_starting) return std::nullopt;
  for (int axis = 0; axis < config::kPanelAxes; ++axis) {
    const int direction = panel_.jogging[static_cast<std::size_t>(axis)];
    if (direction == 0) continue;
    const auto input = static_cast<config::PanelInput>(
        static_cast<int>(direction > 0 ? config::PanelInput::jog_plus_x
                                       : config::PanelInput::jog_minus_x) +
        axis);
    return ManualHolder{"the panel's " + config::panel_input_key(input) + " button", true, axis};
  }
  if (client_jog_axes_ == 0) return std::nullopt;
  const bool one = (client_jog_axes_ & (client_jog_axes_ - 1)) == 0;
  return ManualHolder{client_jog_by_, false, one ? std::countr_zero(client_jog_axes_) : -1};
}

void Task::client_may_jog() const {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI block is running");
  // One hand on the machine: the panel's while it jogs, or another client's.
  const motion::Status status = motion_.status();
  const auto holder = manual_holder(status);
  if (!holder) return;
  const std::string axis =
      holder->axis >= config::kMaxAxes ? " joint " + std::to_string(holder->axis - config::kMaxAxes)
      : holder->axis >= 0
          ? " " + std::string(1, config::kAxisLetters[static_cast<std::size_t>(holder->axis)])
          : std::string();
  if (status.panel.mpg_jogging) {
    throw TaskError(TaskErrorKind::busy,
                    holder->by + " is jogging" + axis + ": wait until it rests");
  }
  if (holder->panel) throw TaskError(TaskErrorKind::busy, holder->by + " is jogging");
  if (holder->by != jog_actor()) {
    throw TaskError(TaskErrorKind::busy,
                    holder->by + " is jogging" + axis + ": wait until the jog stops");
  }
}

std::string Task::jog_actor() const {
  return events_.actor().empty() ? std::string("a client") : events_.actor();
}

void Task::client_jogs(int axis) {
  client_jog_axes_ |= 1u << axis;
  client_jog_by_ = jog_actor();
  client_jog_cycle_ = motion_.status().sequence;
}

void Task::jog_start(int axis, double velocity) {
  client_may_jog();
  if (const auto error = motion_.jog_start(axis, velocity); !error.empty())
    throw jog_refused(error);
  client_jogs(axis);
}

void Task::jog_increment(int axis, double distance, double velocity) {
  client_may_jog();
  if (const auto error = motion_.jog_increment(axis, distance, velocity); !error.empty())
    throw jog_refused(error);
  client_jogs(axis);
}

void Task::jog_stop(int axis) {
  if (axis >= 0 && axis < 32) client_jog_axes_ &= ~(1u << axis);
  motion_.jog_stop(axis);
}

void Task::set_feed_override(double ratio) {
  motion_.set_feed_override(ratio);
  spdlog::debug("feed override {}", ratio_text(ratio));
}

void Task::set_rapid_override(double ratio) {
  motion_.set_rapid_override(ratio);
  spdlog::debug("rapid override {}", ratio_text(ratio));
}

void Task::set_spindle_override(double ratio) {
  motion_.set_spindle_override(ratio);
  spdlog::debug("spindle override {}", ratio_text(ratio));
}

}  // namespace cncd::daemon
