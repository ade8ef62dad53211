// The operator's manual controls: jogs and the overrides.
#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "task.hpp"

namespace cncd::daemon {

namespace {

TaskError jog_refused(const std::string& reason) {
  const bool busy = reason == "the machine is moving" || reason == "the machine is jogging";
  return TaskError(busy ? TaskErrorKind::busy : TaskErrorKind::wrong_state, reason);
}

// "1.5 (150 %)"
std::string ratio_text(double ratio) {
  return fmt::format("{:g} ({:g} %)", ratio, ratio * 100.0);
}

}  // namespace

void Task::jog_start(int axis, double velocity) {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI block is running");
  if (const auto error = motion_.jog_start(axis, velocity); !error.empty())
    throw jog_refused(error);
}

void Task::jog_increment(int axis, double distance, double velocity) {
  if (exec_ != ExecState::idle)
    throw TaskError(TaskErrorKind::busy, "a program or MDI block is running");
  if (const auto error = motion_.jog_increment(axis, distance, velocity); !error.empty())
    throw jog_refused(error);
}

void Task::jog_stop(int axis) {
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
