// The operator's manual controls: jogs and the overrides.
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

void Task::client_may_jog() const {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI block is running");
  // One hand on the machine: the panel's, while it jogs.
  const motion::Status status = motion_.status();
  if (status.panel.mpg_jogging) {
    const int axis = status.panel.mpg_axis;
    throw TaskError(
        TaskErrorKind::busy,
        "the panel's MPG is jogging" +
            (axis >= 0 && axis < config::kPanelAxes
                 ? " " + std::string(1, config::kAxisLetters[static_cast<std::size_t>(axis)])
                 : std::string()) +
            ": wait until it rests");
  }
  if (status.motion != motion::MotionState::jogging) return;
  for (int axis = 0; axis < config::kPanelAxes; ++axis) {
    const int direction = panel_.jogging[static_cast<std::size_t>(axis)];
    if (direction == 0) continue;
    throw TaskError(TaskErrorKind::busy,
                    "the panel's " +
                        config::panel_input_key(static_cast<config::PanelInput>(
                            static_cast<int>(direction > 0 ? config::PanelInput::jog_plus_x
                                                           : config::PanelInput::jog_minus_x) +
                            axis)) +
                        " button is jogging");
  }
}

void Task::client_jogs(int axis) {
  client_jog_axes_ |= 1u << axis;
  client_jog_by_ = events_.actor().empty() ? std::string("a client") : events_.actor();
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
