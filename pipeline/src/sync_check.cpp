// What a machine needs to move as a program asks: the axes the moves use; to move in step with
// its spindle, the spindle's position to follow, a spindle that reverses for a rigid tap, and
// axes fast enough for a thread's pitch at the spindle's speed.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "cncd/pipeline/feeder.hpp"

namespace cncd::pipeline {
namespace {

std::string number(double value) {
  std::ostringstream out;
  out.precision(6);
  out << value;
  return out.str();
}

}  // namespace

std::optional<std::string> axis_missing(const config::MachineConfig& machine,
                                        const motion::AxisPose& start,
                                        const motion::AxisPose& end) {
  static constexpr char kLetters[] = "XYZABCUVW";
  for (std::size_t axis = 0; axis < machine.axes.size(); ++axis) {
    if (machine.axes[axis].present || start[axis] == end[axis]) continue;
    return std::string("the move commands ") + kLetters[axis] + ", an axis this machine does " +
           "not have ([TRAJ] COORDINATES = " + machine.coordinates + ")";
  }
  return std::nullopt;
}

namespace {

// What `machine` lacks to know its spindle's position, after "needs the spindle's position: ";
// or nothing.
std::optional<std::string> position_source_missing(const config::MachineConfig& machine) {
  const config::SpindleConfig& sp = machine.spindle;
  // Without [SPINDLE_0] the spindle is ideal: its position is where its command took it.
  if (!sp.present) return std::nullopt;
  switch (sp.driver) {
    case config::SpindleDriver::sim:
      return std::nullopt;
    case config::SpindleDriver::gpio:
      if (sp.encoder_ppr > 0) return std::nullopt;
      return "[SPINDLE_0] has no encoder (ENCODER_A, ENCODER_B, ENCODER_PPR)";
    case config::SpindleDriver::modbus:
      if (sp.position_register >= 0) return std::nullopt;
      return "the Modbus spindle ([SPINDLE_0] DRIVER = modbus) has no POSITION_REGISTER";
    case config::SpindleDriver::none:
      break;
  }
  return std::string("[SPINDLE_0] DRIVER = none");
}

}  // namespace

// Why `machine` cannot do `what`, which needs the spindle's position; or nothing.
static std::optional<std::string> needs_position(const config::MachineConfig& machine,
                                                 const char* what) {
  const auto missing = position_source_missing(machine);
  if (!missing) return std::nullopt;
  const bool no_spindle = machine.spindle.driver == config::SpindleDriver::none;
  return std::string(what) +
         (no_spindle ? " needs a spindle: " : " needs the spindle's position: ") + *missing;
}

std::optional<std::string> spindle_position_missing(const config::MachineConfig& machine) {
  return needs_position(machine, "spindle-synchronized motion (G33, G33.1, rigid tapping)");
}

std::optional<std::string> spindle_cannot_orient(const config::MachineConfig& machine) {
  return needs_position(machine, "spindle orientation (M19, G87)");
}

std::optional<std::string> spindle_cannot_reverse(const config::MachineConfig& machine) {
  const config::SpindleConfig& sp = machine.spindle;
  if (!sp.present || sp.driver == config::SpindleDriver::none) return std::nullopt;
  if (sp.max_reverse_velocity == 0) {
    return "rigid tapping turns the spindle back out of the hole, and [SPINDLE_0] "
           "MAX_REVERSE_VELOCITY = 0 forbids reverse";
  }
  if (sp.driver == config::SpindleDriver::modbus && sp.command_reverse == sp.command_stop) {
    return "rigid tapping turns the spindle back out of the hole, and the Modbus spindle cannot "
           "reverse ([SPINDLE_0] COMMAND_REVERSE = COMMAND_STOP)";
  }
  return std::nullopt;
}

std::optional<std::string> thread_too_fast(const config::MachineConfig& machine,
                                           const motion::AxisPose& start,
                                           const motion::AxisPose& end, double per_rev, double rpm,
                                           int direction, double programmed) {
  const config::SpindleConfig& sp = machine.spindle;
  if (sp.present && rpm > 0) {
    // The speed the spindle is told at 100 % override, within its limits that way.
    rpm = direction < 0 ? std::clamp(rpm, sp.min_reverse_velocity,
                                     std::max(sp.min_reverse_velocity, sp.max_reverse_velocity))
                        : std::clamp(rpm, sp.min_forward_velocity,
                                     std::max(sp.min_forward_velocity, sp.max_forward_velocity));
  }
  if (!(rpm > 0) || !(per_rev > 0) || !std::isfinite(rpm * per_rev)) return std::nullopt;
  double length = 0;
  for (std::size_t i = 0; i < machine.axes.size() && i < start.size(); ++i) {
    if (machine.axes[i].present) length += (end[i] - start[i]) * (end[i] - start[i]);
  }
  length = std::sqrt(length);
  if (!(length > 1e-9)) return std::nullopt;
  // The path follows the helix at per_rev x rev/s; each axis at its share of that. The one
  // furthest over its MAX_VELOCITY (or the path over [TRAJ] MAX_LINEAR_VELOCITY) is named.
  const double helix = per_rev * rpm / 60.0;
  double worst = 1;
  std::string why;
  const auto speed = [&](const char* unit, double v) { return number(v) + " " + unit + "/s"; };
  const char* linear = machine.linear_units == config::LinearUnits::inch ? "inch" : "mm";
  for (std::size_t i = 0; i < machine.axes.size() && i < start.size(); ++i) {
    const config::AxisConfig& axis = machine.axes[i];
    if (!axis.present || !(axis.max_velocity > 0)) continue;
    const double need = helix * std::abs(end[i] - start[i]) / length;
    if (need <= axis.max_velocity * worst * (1 + 1e-9)) continue;
    worst = need / axis.max_velocity;
    const char letter = config::kAxisLetters[i];
    const char* unit = i >= 3 && i < 6 ? "deg" : linear;  // A, B, C turn
    why = std::string("needs ") + letter + " at " + speed(unit, need) + "; [AXIS_" + letter +
          "] MAX_VELOCITY is " + speed(unit, axis.max_velocity);
  }
  if (machine.max_linear_velocity > 0 && helix > machine.max_linear_velocity * worst * (1 + 1e-9)) {
    worst = helix / machine.max_linear_velocity;
    why = "needs a path speed of " + speed(linear, helix) + "; [TRAJ] MAX_LINEAR_VELOCITY is " +
          speed(linear, machine.max_linear_velocity);
  }
  if (why.empty()) return std::nullopt;
  const std::string at =
      std::abs(rpm - programmed) < 1e-9 ? "S" + number(rpm) : number(rpm) + " rpm";
  return "G33 at " + at + " with " + number(per_rev) + " " + linear + " per revolution " + why +
         ": the thread would fall behind the spindle (at most " + number(rpm / worst) +
         " rpm at this pitch, or at most " + number(per_rev / worst) + " " + linear +
         " per revolution at this speed)";
}

}  // namespace cncd::pipeline
