// Task::status(): the status snapshot as the control protocol's JSON object.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "task.hpp"

namespace cncd::daemon {

using nlohmann::json;

namespace {
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
    case motion::MotionState::jogging:
      return "jogging";
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

template <typename Pose>
json axes_object(const config::MachineConfig& config, const Pose& pose) {
  json out = json::object();
  for (std::size_t i = 0; i < config::kAxisLetters.size(); ++i) {
    if (!config.axes[i].present) continue;
    const char letter = static_cast<char>(config::kAxisLetters[i] - 'A' + 'a');
    out[std::string(1, letter)] = pose[i];
  }
  return out;
}

// Machine coordinates -> work coordinates, all in machine units: the inverse of LinuxCNC's
// machine = rotate_xy(work + g92, rotation) + g5x + tool.
motion::AxisPose work_pose(const motion::AxisPose& machine, const interp::InterpState& st) {
  motion::AxisPose p = machine;
  for (std::size_t a = 0; a < p.size() && a < st.g5x_offset.size(); ++a)
    p[a] -= st.g5x_offset[a] + st.tool_offset[a];
  if (st.rotation_deg != 0.0) {
    const double angle = -st.rotation_deg * std::numbers::pi / 180.0;
    const double x = p[0] * std::cos(angle) - p[1] * std::sin(angle);
    const double y = p[0] * std::sin(angle) + p[1] * std::cos(angle);
    p[0] = x;
    p[1] = y;
  }
  for (std::size_t a = 0; a < p.size() && a < st.g92_offset.size(); ++a)
    p[a] -= st.g92_offset[a];
  return p;
}

// 593 -> "G59.3": LinuxCNC's codes are ten times the number.
std::string code_name(char letter, int code) {
  std::string out(1, letter);
  out += std::to_string(code / 10);
  if (code % 10 != 0) out += "." + std::to_string(code % 10);
  return out;
}

// The active codes in LinuxCNC's modal-group order, without the line number and empty groups.
json active_g_codes(const interp::InterpState& st) {
  json out = json::array();
  for (std::size_t i = 1; i < st.gcodes.size(); ++i) {
    if (st.gcodes[i] >= 0) out.push_back(code_name('G', st.gcodes[i]));
  }
  return out;
}

// Each joint's switches and drive, as the servo thread read them in its last period.
json joints_array(const motion::Status& s) {
  json out = json::array();
  for (int j = 0; j < s.joint_count; ++j) {
    const auto k = static_cast<std::size_t>(j);
    const motion::JointStatus& joint = s.joints[k];
    out.push_back({{"homed", s.homed[k]},
                   {"fault", s.joint_fault[k]},
                   {"min_limit", joint.min_limit},
                   {"max_limit", joint.max_limit},
                   {"home_switch", joint.home_switch},
                   {"at_min_soft_limit", joint.at_min_soft_limit},
                   {"at_max_soft_limit", joint.at_max_soft_limit},
                   {"driver", std::string(joint.driver)},
                   {"enabled", joint.enabled},
                   {"drive_fault", joint.drive_fault},
                   {"stale", joint.stale}});
  }
  return out;
}

json active_m_codes(const interp::InterpState& st) {
  json out = json::array();
  for (std::size_t i = 1; i < st.mcodes.size(); ++i) {
    if (st.mcodes[i] >= 0) out.push_back("M" + std::to_string(st.mcodes[i]));
  }
  return out;
}
}  // namespace

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

std::string coord_system_name(int system) {
  return code_name('G', system < 7 ? 530 + 10 * system : 584 + system);
}

void Task::set_exec(ExecState next) {
  const auto now = std::chrono::steady_clock::now();
  if (exec_ == ExecState::paused && next != ExecState::paused)
    paused_s_ += std::chrono::duration<double>(now - paused_since_).count();
  if (exec_ != ExecState::paused && next == ExecState::paused) paused_since_ = now;
  exec_ = next;
}

json Task::time_estimate(std::uint64_t moves_done) const {
  const PlanEstimate estimate = estimator_.get();
  json out = {{"estimated_s", nullptr}, {"remaining_s", nullptr}, {"remaining_reason", ""}};
  if (program_path_.empty()) return out;
  if (estimate.state != PlanEstimate::State::done) {
    out["remaining_reason"] = estimate.reason;
    return out;
  }
  const double total = estimate.estimated_s;
  out["estimated_s"] = total;
  if (exec_ == ExecState::idle || mode_ != Mode::automatic) {
    out["remaining_s"] = last_result_ == "done" && exec_ == ExecState::idle ? 0.0 : total;
    return out;
  }
  const auto& starts = *estimate.move_start_s;
  // Time spent moving, kept within the estimated window of the move under way so that a feed
  // override or a hold cannot drift it away.
  double active = moving_s();
  if (!from_top_) {
    // Run from line: the estimate from the line's first move on. The traverse to the line's
    // start was not estimated: until it ends the whole rest of the program remains.
    // Looked up once a run: a status request must not walk millions of moves.
    if (first_move_.lines != estimate.move_line || first_move_.line != run_from_line_) {
      const auto& lines = *estimate.move_line;
      const auto first = std::find_if(lines.begin(), lines.end(),
                                      [&](std::int32_t line) { return line >= run_from_line_; });
      first_move_ = {estimate.move_line, run_from_line_,
                     static_cast<std::uint64_t>(first - lines.begin())};
    }
    if (first_move_.index >= estimate.move_line->size() ||
        starts.size() != estimate.move_line->size()) {
      out["remaining_s"] = 0.0;
      return out;
    }
    const std::uint64_t k0 = first_move_.index;
    if (skip_moved_ && !approach_done_s_) {
      out["remaining_s"] = total - starts[k0];
      return out;
    }
    moves_done += k0 - (skip_moved_ ? 1 : 0);
    active += starts[k0] - approach_done_s_.value_or(0.0);
  }
  if (moves_done >= starts.size()) {
    out["remaining_s"] = 0.0;
    return out;
  }
  const double begin = starts[moves_done];
  const double end = moves_done + 1 < starts.size() ? starts[moves_done + 1] : total;
  out["remaining_s"] = std::max(0.0, total - std::clamp(active, begin, std::max(begin, end)));
  return out;
}

double Task::servo_seconds_since(std::uint64_t cycles) const {
  const std::uint64_t now = motion_.status().rt.cycles;
  return static_cast<double>(now > cycles ? now - cycles : 0) *
         static_cast<double>(config_.servo_period_ns) * 1e-9;
}

double Task::moving_s() const {
  const auto until = exec_ == ExecState::paused ? paused_since_ : std::chrono::steady_clock::now();
  return std::chrono::duration<double>(until - started_at_).count() - paused_s_;
}

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
  const double motion_time =
      exec_ == ExecState::idle ? motion_s_ : servo_seconds_since(started_cycles_);
  // Between steps nothing is read ahead: the interpreter's line is the one just carried out.
  const int line = exec_ == ExecState::idle                  ? 0
                   : stepping_ && exec_ == ExecState::paused ? interp_->current_line()
                                                             : s.line;
  const std::uint64_t moves =
      exec_ == ExecState::idle ? moves_completed_ : s.moves_done - moves_done_base_;
  const double progress =
      exec_ != ExecState::idle
          ? (program_lines_ == 0 ? 0.0 : std::min(1.0, static_cast<double>(line) / program_lines_))
      : last_result_ == "done" ? 1.0
                               : 0.0;
  const json times = time_estimate(moves);
  const interp::InterpState st = interp_->state();
  json tool_entry = nullptr;
  if (const auto entry = st.tool_in_spindle != 0 ? interp_->tool(st.tool_in_spindle) : std::nullopt)
    tool_entry = {{"diameter", entry->diameter}, {"comment", entry->comment}};
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
      {"joints", joints_array(s)},
      {"fault", std::string(s.fault_reason)},
      {"position",
       {{"commanded", axes_object(config_, s.commanded)},
        {"actual", axes_object(config_, s.actual)}}},
      {"position_restored", position_restored_},
      {"work_position",
       {{"commanded", axes_object(config_, work_pose(s.commanded, st))},
        {"actual", axes_object(config_, work_pose(s.actual, st))}}},
      {"velocity", s.velocity},
      {"distance_to_go", s.distance_to_go},
      {"overrides",
       {{"feed", s.feed_override}, {"rapid", s.rapid_override}, {"spindle", spindle_override_}}},
      {"program",
       {{"path", program_path_},
        {"opening", opening_ ? opening_->path : std::string()},
        {"line", line},
        {"total_lines", program_lines_},
        {"progress", progress},
        {"stepping", stepping_},
        {"moves", moves},
        {"elapsed_s", elapsed},
        {"motion_s", motion_time},
        {"estimated_s", times["estimated_s"]},
        {"remaining_s", times["remaining_s"]},
        {"remaining_reason", times["remaining_reason"]},
        {"result", last_result_},
        {"error", last_error_}}},
      {"spindle",
       {{"direction", feeder_->spindle_direction},
        {"speed", feeder_->spindle_speed * spindle_override_},
        {"programmed_speed", feeder_->spindle_speed},
        {"override", spindle_override_}}},
      {"coolant", {{"mist", feeder_->mist}, {"flood", feeder_->flood}}},
      {"tool",
       {{"number", st.tool_in_spindle},
        {"prepared", st.tool_prepared},
        {"length_offset", axes_object(config_, st.tool_offset)},
        {"entry", tool_entry}}},
      {"offsets",
       {{"coord_system", coord_system_name(st.coord_system)},
        {"index", st.coord_system},
        {"g5x", axes_object(config_, st.g5x_offset)},
        {"rotation", st.rotation_deg},
        {"g92", axes_object(config_, st.g92_offset)}}},
      {"gcodes", active_g_codes(st)},
      {"mcodes", active_m_codes(st)},
      {"feed_rate", st.feed_rate},
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
