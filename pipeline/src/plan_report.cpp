// The plan simulation's figures as cncd-check --plan prints them.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include <nlohmann/json.hpp>

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
  text += std::string("peak velocity (") + unit +
          "/s, % of MAX_VELOCITY):" + axis_row(machine, result.peak_velocity, false) + "\n";
  text += std::string("peak acceleration (") + unit +
          "/s^2, % of MAX_ACCELERATION):" + axis_row(machine, result.peak_acceleration, true) +
          "\n";
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
    const char letter = static_cast<char>(config::kAxisLetters[i] - 'A' + 'a');
    axes[std::string(1, letter)] = {
        {"peak_velocity", result.peak_velocity[i]},
        {"max_velocity", axis.max_velocity},
        {"velocity_ratio", ratio(result.peak_velocity[i], axis.max_velocity)},
        {"peak_acceleration", result.peak_acceleration[i]},
        {"max_acceleration", axis.max_acceleration},
        {"acceleration_ratio", ratio(result.peak_acceleration[i], axis.max_acceleration)}};
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
      {"axes", axes},
      {"max_deviation", result.max_deviation},
      {"max_deviation_line", result.max_deviation_line},
      {"planner_cpu_s", result.planner_cpu_s},
      {"servo_cpu_s", result.servo_cpu_s},
      {"line_start_s", lines}};
  return out.dump();
}

}  // namespace cncd::pipeline
