// Offline plan simulation: runs a program through the interpreter, the ProgramFeeder the
// daemon uses, the real Planner and a ServoLoop on simulated drives, cycle by cycle in virtual
// time (no thread, no sleeping), and measures what the machine would do: the cycle time, its
// lower bounds, peak axis velocity and acceleration, the deviation from the programmed path and
// when each move starts. Used by `cncd-check --plan`, the daemon's remaining-time estimate and
// the planner benchmark. Any thread; no shared state.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/interpreter.hpp"
#include "cncd/motion/segment.hpp"
#include "cncd/motion/types.hpp"
#include "cncd/pipeline/program_check.hpp"

namespace cncd::pipeline {

// One servo period of the simulated motion, as PlanSimOptions::on_period hands it on.
struct PlanSample {
  double t = 0;                 // s, from the program's start, at the end of the period
  motion::AxisPose axes{};      // the commanded axes (machine coordinates), as on_sample's
  motion::JointArray joints{};  // the joints' commanded positions, [JOINT_n] order
  // On a machine with TCP (Kinematics::has_tcp()): the tool tip in the part's frame for those
  // joints, and whether the segment under way (or the last one) was planned under TCP.
  motion::AxisPose tip{};
  bool tcp = false;
  double spindle = 0;  // revolutions, as on_sample's
};

struct PlanSimOptions {
  interp::InterpOptions interp;
  // Where the machine stands when the program starts (machine coordinates and units); unset =
  // program zero in the coordinate system the program starts in.
  std::optional<interp::Pose> start_machine;
  // Run from this line (> 1) as the daemon does: the lines before it read for their state,
  // then the way to the line's start from start_machine (ProgramRunner::skip_to).
  int from_line = 0;
  // The simulation stops (PlanSimResult::stopped) after this much wall-clock time, after this
  // much simulated machine time, or past this many moves; 0 = no limit.
  double max_wall_s = 0;
  double max_machine_s = 0;
  std::size_t max_moves = 0;
  // Measure peaks and path deviation (a little slower); the daemon's estimate does without.
  bool measure = true;
  // Called once per servo period with the time (s, from the program's start), the commanded
  // axis positions (machine coordinates) at the end of that period and the spindle's position
  // then (revolutions, signed: forward counts up), as the next period reads it.
  std::function<void(double, const motion::AxisPose&, double)> on_sample;
  // The same period with the joints and the TCP state (the trajectory CSV).
  std::function<void(const PlanSample&)> on_period;
  // Called with every programmed move, in order, as the planner plans it alone: the geometry
  // the bounds use, before a blend or a merge shortens it.
  std::function<void(const motion::Segment&)> on_move;
  // Called with every segment the planner hands to the servo loop, in order: the trimmed lines,
  // blend arcs and arcs with the limits it set on them.
  std::function<void(const motion::Segment&)> on_segment;
  // Set from another thread to stop the simulation early (PlanSimResult::stopped says so).
  const std::atomic<bool>* cancel = nullptr;
};

struct PlanSimResult {
  // The interpreter's error, a move the planner refused, or why the simulation stopped early;
  // the figures below then cover the part simulated.
  std::optional<CheckProblem> error;
  std::optional<CheckProblem> stopped;
  bool complete() const { return !error && !stopped; }

  double period_s = 0;
  std::uint64_t cycles = 0;  // servo periods from the program's start until motion ended
  double cycle_time_s = 0;   // cycles * period
  // Sum over the programmed moves of length / feed (capped by the axis limits along the move),
  // traverses at the fastest speed the axes allow along them, dwells included. Blends that
  // cut corners short may come in a little under it.
  double feed_bound_s = 0;
  // Every move a rest-to-rest trapezoid at that speed within the axes' accelerations, dwells
  // included: what a planner stopping after every move needs at least.
  double exact_stop_bound_s = 0;
  std::size_t moves = 0;  // moves planned (dwells included)
  // Per axis (config::axis_index), from finite differences of the commanded positions per
  // servo period: the largest |velocity| (units/s) and |acceleration| (units/s^2).
  motion::AxisPose peak_velocity{};
  motion::AxisPose peak_acceleration{};
  // The same per joint ([JOINT_n] order, joint units) from the joints' commanded positions:
  // what the motors do where a joint is not an axis of its own (corexy's belts, a trunnion's
  // X Y Z under TCP). The first joint_count entries are the machine's.
  int joint_count = 0;
  motion::JointArray joint_peak_velocity{};
  motion::JointArray joint_peak_acceleration{};
  // Largest XYZ distance from a commanded position to the programmed path near the move under
  // way (units), and the program line where it happened.
  double max_deviation = 0;
  int max_deviation_line = 0;
  // For each programmed move in order (as Status::moves_done counts them): its source line
  // and when it starts (s, virtual time), which is when the move before it is complete.
  std::vector<std::int32_t> move_line;
  std::vector<double> move_start_s;
  double planner_cpu_s = 0;  // thread CPU time spent in Planner::push
  double servo_cpu_s = 0;    // thread CPU time spent in ServoLoop::cycle (with `measure`)
  double wall_s = 0;         // wall-clock time of the whole simulation
};

// Simulates `program` on `machine`. Never writes the parameter file or the tool table.
PlanSimResult simulate_plan(const config::MachineConfig& machine,
                            const std::filesystem::path& program, const PlanSimOptions& options);

// The human report cncd-check --plan prints, and the same as one JSON object (one line).
std::string describe_plan(const config::MachineConfig& machine, const PlanSimResult& result);
std::string plan_json(const config::MachineConfig& machine, const PlanSimResult& result);

}  // namespace cncd::pipeline
