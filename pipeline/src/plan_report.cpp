// The plan simulation's figures as cncd-check --plan prints them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include <nlohmann/json.hpp>

#include "cncd/motion/kinematics.hpp"
#include "cncd/pipeline/plan_sim.hpp"

namespace cncd::pipeline {
namespace {

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

double ratio(double value, double bound) {
  return bound > 0 ? value / bound : 0.0;
}

std::string axis_row(const config::MachineConfig& machine, const motion::AxisPose& peaks,
                     bool acceleration) {
  std::string row;
  for (std::size_t i = 0; i < config::kAxisLetters.size(); ++i) {
    const auto& axis = machine.axes[i];
    if (!axis.present) continue;
    const double limit = acceleration ? axis.max_acceleration : axis.max_velocity;
    row += std::string("  ") + config::kAxisLetters[i] + " " + format("%.3f", peaks[i]) + " (" +
           format("%.2f", 100.0 * ratio(peaks[i], limit)) + " %)";
  }
  return row;
}

// "x" for axis 0, as the JSON's keys name the axes.
std::string axis_key(std::size_t axis) {
  return std::string(1, static_cast<char>(config::kAxisLetters[axis] - 'A' + 'a'));
}

// Joint j's row entry: "J0" and, where the joint drives one axis alone, that axis ("J3 A").
std::string joint_name(const motion::Kinematics& kins, int j) {
  const int axis = kins.axis_of_joint(j);
  std::string name = "J" + std::to_string(j);
  if (axis >= 0) name += std::string(" ") + config::kAxisLetters[static_cast<std::size_t>(axis)];
  return name;
}

std::string joint_row(const config::MachineConfig& machine, const motion::Kinematics& kins,
                      const PlanSimResult& result, bool acceleration) {
  std::string row;
  for (int j = 0; j < result.joint_count && static_cast<std::size_t>(j) < machine.joints.size();
       ++j) {
    const auto& joint = machine.joints[static_cast<std::size_t>(j)];
    const double peak = (acceleration ? result.joint_peak_acceleration
                                      : result.joint_peak_velocity)[static_cast<std::size_t>(j)];
    const double limit = acceleration ? joint.max_acceleration : joint.max_velocity;
    row += "  " + joint_name(kins, j) + " " + format("%.3f", peak) + " (" +
           format("%.2f", 100.0 * ratio(peak, limit)) + " %)";
  }
  return row;
}

// "mm/s" (`per` "/s"), or "mm/s and deg/s" where some of the axes or joints turn (`angular`).
std::string units_text(const config::MachineConfig& machine, bool angular, const char* per) {
  std::string text =
      std::string(machine.linear_units == config::LinearUnits::inch ? "in" : "mm") + per;
  if (!angular) return text;
  static constexpr const char* kAngular[] = {"deg", "rad", "grad"};
  return text + " and " + kAngular[static_cast<int>(machine.angular_units)] + per;
}

// Whether the machine turns an axis (A, B, C) or has an angular joint.
bool has_angular_axes(const config::MachineConfig& machine) {
  for (std::size_t i = 3; i < 6 && i < machine.axes.size(); ++i) {
    if (machine.axes[i].present) return true;
  }
  return false;
}
bool has_angular_joints(const config::MachineConfig& machine) {
  return std::any_of(machine.joints.begin(), machine.joints.end(),
                     [](const auto& joint) { return joint.type == config::JointType::angular; });
}

nlohmann::json problem_json(const std::optional<CheckProblem>& problem) {
  if (!problem) return nullptr;
  return problem->to_string();
}

}  // namespace

std::string describe_plan(const config::MachineConfig& machine, const PlanSimResult& result) {
  const char* unit = machine.linear_units == config::LinearUnits::inch ? "in" : "mm";
  std::string text = "plan: " + std::to_string(result.moves) + " moves, " +
                     std::to_string(result.cycles) + " servo periods of " +
                     format("%g", result.period_s * 1e3) + " ms" +
                     (result.complete() ? "" : " (incomplete)") + "\n";
  text += "cycle time: " + format("%.3f", result.cycle_time_s) + " s\n";
  text += "feed-limited bound: " + format("%.3f", result.feed_bound_s) + " s (cycle time " +
          format("%.4f", ratio(result.cycle_time_s, result.feed_bound_s)) + " x)\n";
  text += "exact-stop bound: " + format("%.3f", result.exact_stop_bound_s) + " s (cycle time " +
          format("%.4f", ratio(result.cycle_time_s, result.exact_stop_bound_s)) + " x)\n";
  if (machine.kinematics == "trivkins") {
    // Each joint moves as its axis: the axes' figures are the joints'.
    text += std::string("peak velocity (") + unit +
            "/s, % of MAX_VELOCITY):" + axis_row(machine, result.peak_velocity, false) + "\n";
    text += std::string("peak acceleration (") + unit +
            "/s^2, % of MAX_ACCELERATION):" + axis_row(machine, result.peak_acceleration, true) +
            "\n";
  } else {
    // The axes as the joints put them (machine coordinates), then the joints themselves.
    const auto kins = motion::make_kinematics(machine);
    const bool angular_axes = has_angular_axes(machine);
    const bool angular_joints = has_angular_joints(machine);
    text += "peak axis velocity (machine coordinates, " + units_text(machine, angular_axes, "/s") +
            ", % of [AXIS_L] MAX_VELOCITY):" + axis_row(machine, result.peak_velocity, false) +
            "\n";
    text += "peak axis acceleration (machine coordinates, " +
            units_text(machine, angular_axes, "/s^2") + ", % of [AXIS_L] MAX_ACCELERATION):" +
            axis_row(machine, result.peak_acceleration, true) + "\n";
    text += "peak joint velocity (" + units_text(machine, angular_joints, "/s") +
            ", % of [JOINT_n] MAX_VELOCITY):" + joint_row(machine, *kins, result, false) + "\n";
    text += "peak joint acceleration (" + units_text(machine, angular_joints, "/s^2") +
            ", % of [JOINT_n] MAX_ACCELERATION):" + joint_row(machine, *kins, result, true) + "\n";
  }
  text += "max path deviation: " + format("%.6f", result.max_deviation) + " " + unit +
          (result.max_deviation_line > 0 ? " at line " + std::to_string(result.max_deviation_line)
                                         : std::string()) +
          "\n";
  const double moves = static_cast<double>(std::max<std::size_t>(result.moves, 1));
  text += "planner CPU: " + format("%.3f", result.planner_cpu_s * 1e6 / moves) +
          " us per move; servo loop CPU: " + format("%.3f", result.servo_cpu_s * 1e6 / moves) +
          " us per move, " +
          format("%.3f", result.servo_cpu_s * 1e6 /
                             static_cast<double>(std::max<std::uint64_t>(result.cycles, 1))) +
          " us per period\n";
  return text;
}

std::string plan_json(const config::MachineConfig& machine, const PlanSimResult& result) {
  nlohmann::json axes = nlohmann::json::object();
  for (std::size_t i = 0; i < config::kAxisLetters.size(); ++i) {
    const auto& axis = machine.axes[i];
    if (!axis.present) continue;
    axes[axis_key(i)] = {
        {"peak_velocity", result.peak_velocity[i]},
        {"max_velocity", axis.max_velocity},
        {"velocity_ratio", ratio(result.peak_velocity[i], axis.max_velocity)},
        {"peak_acceleration", result.peak_acceleration[i]},
        {"max_acceleration", axis.max_acceleration},
        {"acceleration_ratio", ratio(result.peak_acceleration[i], axis.max_acceleration)}};
  }
  // Every joint, [JOINT_n] order: the axis it drives alone, null where it drives none alone.
  nlohmann::json joints = nlohmann::json::array();
  const auto kins = motion::make_kinematics(machine);
  for (int j = 0; j < result.joint_count && static_cast<std::size_t>(j) < machine.joints.size();
       ++j) {
    const auto k = static_cast<std::size_t>(j);
    const auto& joint = machine.joints[k];
    const int axis = kins->axis_of_joint(j);
    joints.push_back(
        {{"joint", j},
         {"axis", axis >= 0 ? nlohmann::json(axis_key(static_cast<std::size_t>(axis)))
                            : nlohmann::json(nullptr)},
         {"peak_velocity", result.joint_peak_velocity[k]},
         {"max_velocity", joint.max_velocity},
         {"velocity_ratio", ratio(result.joint_peak_velocity[k], joint.max_velocity)},
         {"peak_acceleration", result.joint_peak_acceleration[k]},
         {"max_acceleration", joint.max_acceleration},
         {"acceleration_ratio", ratio(result.joint_peak_acceleration[k], joint.max_acceleration)}});
  }
  // When each line first starts moving, in program order.
  nlohmann::json lines = nlohmann::json::array();
  std::set<std::int32_t> seen;
  // The moves planned and the moves started can differ in number: only those with both count.
  const std::size_t moves = std::min(result.move_line.size(), result.move_start_s.size());
  for (std::size_t i = 0; i < moves; ++i) {
    if (!std::isfinite(result.move_start_s[i]) || !seen.insert(result.move_line[i]).second)
      continue;
    lines.push_back({result.move_line[i], result.move_start_s[i]});
  }
  const nlohmann::json out = {
      {"complete", result.complete()},
      {"error", problem_json(result.error)},
      {"stopped", problem_json(result.stopped)},
      {"moves", result.moves},
      {"period_s", result.period_s},
      {"cycles", result.cycles},
      {"cycle_time_s", result.cycle_time_s},
      {"feed_bound_s", result.feed_bound_s},
      {"feed_bound_ratio", ratio(result.cycle_time_s, result.feed_bound_s)},
      {"exact_stop_bound_s", result.exact_stop_bound_s},
      {"exact_stop_ratio", ratio(result.cycle_time_s, result.exact_stop_bound_s)},
      {"kinematics", machine.kinematics},
      {"axes", axes},
      {"joints", joints},
      {"max_deviation", result.max_deviation},
      {"max_deviation_line", result.max_deviation_line},
      {"planner_cpu_s", result.planner_cpu_s},
      {"servo_cpu_s", result.servo_cpu_s},
      {"line_start_s", lines}};
  return out.dump();
}

}  // namespace cncd::pipeline
