// Task::status(): the status snapshot as the control protocol's JSON object.
#include <filesystem>
#include <string>

#include "task.hpp"

namespace cncd::daemon {

using nlohmann::json;

namespace {
const char* machine_state_name(motion::MachineState state) {
  switch (state) {
    case motion::MachineState::estop:
      return "estop";
    case motion::MachineState::off:
      return "off";
    case motion::MachineState::on:
      return "on";
  }
  return "estop";
}

const char* motion_state_name(motion::MotionState state) {
  switch (state) {
    case motion::MotionState::idle:
      return "idle";
    case motion::MotionState::moving:
      return "moving";
    case motion::MotionState::pausing:
      return "pausing";
    case motion::MotionState::paused:
      return "paused";
    case motion::MotionState::stopping:
      return "stopping";
    case motion::MotionState::homing:
      return "homing";
  }
  return "idle";
}

const char* exec_state_name(ExecState state) {
  switch (state) {
    case ExecState::idle:
      return "idle";
    case ExecState::running:
      return "running";
    case ExecState::paused:
      return "paused";
  }
  return "idle";
}

json axes_object(const config::MachineConfig& config, const motion::AxisPose& pose) {
  json out = json::object();
  for (std::size_t i = 0; i < config::kAxisLetters.size(); ++i) {
    if (!config.axes[i].present) continue;
    const char letter = static_cast<char>(config::kAxisLetters[i] - 'A' + 'a');
    out[std::string(1, letter)] = pose[i];
  }
  return out;
}
}  // namespace

std::string Task::summary() const {
  const motion::Status s = motion_.status();
  std::string out = machine_state_name(s.machine);
  if (s.fault_reason[0] != '\0') out += ", fault: " + std::string(s.fault_reason);
  if (exec_ != ExecState::idle) {
    out += std::string(", ") + exec_state_name(exec_) + " " +
           std::filesystem::path(program_path_).filename().string();
  }
  return out;
}

json Task::status() const {
  const motion::Status s = motion_.status();
  json homed = json::array();
  json joint_fault = json::array();
  for (int j = 0; j < s.joint_count; ++j) {
    homed.push_back(s.homed[static_cast<std::size_t>(j)]);
    joint_fault.push_back(s.joint_fault[static_cast<std::size_t>(j)]);
  }
  const double elapsed =
      exec_ == ExecState::idle
          ? elapsed_s_
          : std::chrono::duration<double>(std::chrono::steady_clock::now() - started_at_).count();
  const int line = exec_ == ExecState::idle ? 0 : s.line;
  const std::uint64_t moves =
      exec_ == ExecState::idle ? moves_completed_ : s.segments_done - moves_done_base_;
  return json{
      {"state", machine_state_name(s.machine)},
      {"exec", exec_state_name(exec_)},
      {"mode", mode_ == Mode::mdi         ? "mdi"
               : mode_ == Mode::automatic ? "auto"
                                          : "manual"},
      {"motion", motion_state_name(s.motion)},
      {"units", config_.linear_units == config::LinearUnits::inch ? "inch" : "mm"},
      {"homed", homed},
      {"joint_fault", joint_fault},
      {"fault", std::string(s.fault_reason)},
      {"position",
       {{"commanded", axes_object(config_, s.commanded)},
        {"actual", axes_object(config_, s.actual)}}},
      {"velocity", s.velocity},
      {"program",
       {{"path", program_path_},
        {"line", line},
        {"total_lines", program_lines_},
        {"moves", moves},
        {"elapsed_s", elapsed},
        {"result", last_result_},
        {"error", last_error_}}},
      {"spindle", {{"direction", feeder_->spindle_direction}, {"speed", feeder_->spindle_speed}}},
      {"coolant", {{"mist", feeder_->mist}, {"flood", feeder_->flood}}},
      {"tool", feeder_->tool},
      {"rt",
       {{"cycles", s.rt.cycles},
        {"overruns", s.rt.overruns},
        {"wake_error_p50_ns", s.rt.wake_error_p50_ns},
        {"wake_error_p99_ns", s.rt.wake_error_p99_ns},
        {"wake_error_p999_ns", s.rt.wake_error_p999_ns},
        {"wake_error_max_ns", s.rt.wake_error_max_ns},
        {"realtime", s.rt.realtime},
        {"memory_locked", s.rt.memory_locked}}},
  };
}

}  // namespace cncd::daemon
