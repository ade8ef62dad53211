// Task::status(): the status snapshot, and the running time it reports.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "task.hpp"

#include "cncd/pipeline/modal_text.hpp"

namespace cncd::daemon {

namespace {

SyncReport sync_report(const motion::SyncStatus& sync) {
  SyncReport out;
  if (sync.mode == motion::SpindleSync::none) return out;
  out.mode = sync.mode == motion::SpindleSync::tap ? "tap" : "thread";
  static constexpr const char* kPhases[] = {
      "", "spindle_stopping", "tapping_in", "tapping_out", "index", "following", "stopping"};
  out.phase = enum_name(sync.phase, kPhases);
  out.per_rev = sync.per_rev;
  out.progress = sync.progress;
  return out;
}
}  // namespace

PauseWaitReport pause_wait_report(const motion::SyncStatus& sync, int line) {
  PauseWaitReport out;
  if (sync.mode == motion::SpindleSync::none) return out;
  const bool tap = sync.mode == motion::SpindleSync::tap;
  out.kind = tap ? "tap_end" : "thread_end";
  out.line = line;
  out.message = std::string("the feed hold takes effect once the ") +
                (tap ? "tap (G33.1, rigid G84/G74) is back out of the hole"
                     : "thread (G33) has reached its end") +
                " (line " + std::to_string(line) + ")";
  return out;
}

namespace {

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

}  // namespace

const char* machine_state_name(motion::MachineState state) {
  static constexpr const char* kNames[] = {"estop", "off", "on"};
  return enum_name(state, kNames);
}

const char* exec_state_name(ExecState state) {
  static constexpr const char* kNames[] = {"idle", "running", "paused"};
  return enum_name(state, kNames);
}

std::string coord_system_name(int system) {
  return pipeline::code_name('G', system < 7 ? 530 + 10 * system : 584 + system);
}

void Task::set_exec(ExecState next) {
  const auto now = std::chrono::steady_clock::now();
  if (exec_ == ExecState::paused && next != ExecState::paused)
    paused_s_ += std::chrono::duration<double>(now - paused_since_).count();
  if (exec_ != ExecState::paused && next == ExecState::paused) paused_since_ = now;
  exec_ = next;
}

void Task::time_estimate(std::uint64_t moves_done, ProgramReport& out) const {
  const PlanEstimate estimate = estimator_.get();
  if (program_path_.empty()) return;
  if (estimate.state != PlanEstimate::State::done) {
    out.remaining_reason = estimate.reason;
    return;
  }
  const double total = estimate.estimated_s;
  out.estimated_s = total;
  if (exec_ == ExecState::idle || mode_ != Mode::automatic) {
    out.remaining_s = last_result_ == "done" && exec_ == ExecState::idle ? 0.0 : total;
    return;
  }
  const auto& starts = *estimate.move_start_s;
  // Time spent moving, kept within the estimated window of the move under way so that a feed
  // override or a hold cannot drift it away.
  double active = moving_s();
  if (!from_top_) {
    // Run from line: the estimate from the line's first move on. The way to the line's start
    // was not estimated: until it ends the whole rest of the program remains.
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
      out.remaining_s = 0.0;
      return;
    }
    const std::uint64_t k0 = first_move_.index;
    if (runner_->skipped_motion() && !approach_done_s_) {
      out.remaining_s = total - starts[k0];
      return;
    }
    moves_done += k0 - static_cast<std::uint64_t>(runner_->approach_moves());
    active += starts[k0] - approach_done_s_.value_or(0.0);
  }
  if (moves_done >= starts.size()) {
    out.remaining_s = 0.0;
    return;
  }
  const double begin = starts[moves_done];
  const double end = moves_done + 1 < starts.size() ? starts[moves_done + 1] : total;
  out.remaining_s = std::max(0.0, total - std::clamp(active, begin, std::max(begin, end)));
  return;
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

TaskStatus Task::status() const {
  const motion::Status s = motion_.status();
  TaskStatus out;
  out.machine = s.machine;
  out.exec = exec_;
  out.mode = mode_;
  out.motion = s.motion;
  for (int j = 0; j < s.joint_count; ++j) {
    const auto k = static_cast<std::size_t>(j);
    out.joints.push_back(
        {s.homed[k], s.joint_fault[k], s.joints[k], s.joint_commanded[k], s.joint_actual[k]});
  }
  out.fault = s.fault_reason;
  out.manual_holder = manual_holder(s);
  out.commanded = s.commanded;
  out.actual = s.actual;
  if (s.has_tcp) out.tcp = TcpReport{runner_->feeder().tcp(), s.tcp, s.tip_commanded, s.tip_actual};
  out.position_restored = position_restored_;
  out.velocity = s.velocity;
  out.distance_to_go = s.distance_to_go;
  out.axes_to_go = s.axes_to_go;
  out.feed_override = s.feed_override;
  out.rapid_override = s.rapid_override;

  ProgramReport& program = out.program;
  program.path = program_path_;
  program.opening = opening_ ? opening_->path : std::string();
  // Between steps nothing is read ahead: the interpreter's line is the one just carried out.
  program.line = exec_ == ExecState::idle                  ? 0
                 : stepping_ && exec_ == ExecState::paused ? interp_->program_line()
                                                           : s.line;
  program.total_lines = program_lines_;
  program.dialect = interp::dialect_name(program_dialect_);
  program.progress = exec_ != ExecState::idle
                         ? (program_lines_ == 0
                                ? 0.0
                                : std::min(1.0, static_cast<double>(program.line) / program_lines_))
                     : last_result_ == "done" ? 1.0
                                              : 0.0;
  program.stepping = stepping_;
  program.moves = exec_ == ExecState::idle ? moves_completed_ : s.moves_done - moves_done_base_;
  program.elapsed_s =
      exec_ == ExecState::idle
          ? elapsed_s_
          : std::chrono::duration<double>(std::chrono::steady_clock::now() - started_at_).count();
  program.motion_s = exec_ == ExecState::idle ? motion_s_ : servo_seconds_since(started_cycles_);
  time_estimate(program.moves, program);
  program.result = last_result_;
  program.error = last_error_;

  const motion::SpindleStatus& sp = s.spindle;
  out.probe.contact = s.probe.contact;
  out.probe.probing = s.probe.armed;
  if (s.probe.done > 0) {
    out.probe.last_tripped = s.probe.tripped;
    out.probe.last_position = s.probe.position;
  }
  out.spindle.direction = sp.direction;
  out.spindle.programmed_speed = sp.programmed_rpm;
  out.spindle.override_ratio = sp.override_ratio;
  out.spindle.override_enabled = sp.override_enabled;
  out.spindle.speed = sp.css_numerator > 0
                          ? sp.commanded_rpm
                          : sp.programmed_rpm * (sp.override_enabled ? sp.override_ratio : 1.0);
  out.spindle.enabled = sp.enabled;
  out.spindle.commanded_rpm = sp.commanded_rpm;
  out.spindle.actual_rpm = sp.actual_rpm;
  out.spindle.at_speed = sp.at_speed;
  if (sp.has_position) out.spindle.position = sp.revolutions;
  if (sp.css_numerator > 0) out.spindle.css_max_rpm = sp.css_max_rpm;
  out.spindle.orient = sp.orient == 1 ? "orienting" : sp.orient == 2 ? "oriented" : "";
  out.spindle.orient_angle = sp.orient_deg;
  out.sync = sync_report(s.sync);
  if (s.motion == motion::MotionState::pausing) out.pause_wait = pause_wait_report(s.sync, s.line);
  out.mist = s.io.mist;
  out.flood = s.io.flood;
  out.io.douts = s.io.douts;
  out.io.aouts.assign(s.io.aouts.begin(), s.io.aouts.end());
  out.io.dins = s.io.dins;
  out.io.ains.assign(s.io.ains.begin(), s.io.ains.end());
  out.wait = wait_report(s);

  const interp::InterpState st = interp_->state();
  out.work_commanded = work_pose(s.commanded, st);
  out.work_actual = work_pose(s.actual, st);
  // Under G7 the DRO shows X as the program writes it: a diameter.
  out.diameter_mode = st.gcodes[15] == 70;
  if (out.diameter_mode) {
    out.work_commanded[0] *= 2;
    out.work_actual[0] *= 2;
  }
  out.tool.number = st.tool_in_spindle;
  out.tool.prepared = st.tool_prepared;
  out.tool.length_offset = st.tool_offset;
  if (st.tool_in_spindle != 0) out.tool.entry = interp_->tool(st.tool_in_spindle);
  out.offsets = {st.coord_system, st.g5x_offset, st.rotation_deg, st.g92_offset};
  out.gcodes = pipeline::active_g_codes(st);
  out.mcodes = pipeline::active_m_codes(st);
  out.feed_rate = st.feed_rate;
  out.rt = s.rt;
  if (config_.panel.present) out.panel = panel_report(s);
  return out;
}

}  // namespace cncd::daemon
