#include <cstdio>
#include <string>

#include "cncd/config/enum_name.hpp"
#include "cncd/config/machine_config.hpp"

namespace cncd::config {
namespace {

std::string num(double value) {
  if (value <= -1e99) return "-inf";
  if (value >= 1e99) return "+inf";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

std::string or_none(const std::filesystem::path& path) {
  return path.empty() ? std::string("(none)") : path.string();
}

std::string or_none(const std::string& text) {
  return text.empty() ? std::string("(none)") : text;
}

const char* linear_name(LinearUnits units) {
  return units == LinearUnits::inch ? "inch" : "mm";
}

const char* angular_name(AngularUnits units) {
  if (units == AngularUnits::radian) return "radian";
  return units == AngularUnits::grad ? "grad" : "degree";
}

void line(std::string& out, const std::string& text) {
  out += text + "\n";
}

const char* driver_name(SpindleDriver driver) {
  static constexpr const char* kNames[] = {"none", "sim", "gpio", "modbus"};
  return enum_name(driver, kNames);
}

// "  NAME = address as written" for a signal that is given.
void signal_line(std::string& out, const std::string& name, const SignalAddress& a) {
  if (a.given()) line(out, "  " + name + " = " + a.text);
}

const char* table_name(SignalAddress::Table table) {
  return table == SignalAddress::Table::holding ? "holding" : "input";
}

void describe_spindle(std::string& out, const SpindleConfig& s) {
  line(out, "Spindle:      driver " + std::string(driver_name(s.driver)) +
                (s.present ? "" : " (no [SPINDLE_0]: ideal, at speed at once)"));
  if (s.driver == SpindleDriver::none) return;
  line(out, "  forward " + num(s.min_forward_velocity) + " .. " + num(s.max_forward_velocity) +
                " rpm, reverse " +
                (s.max_reverse_velocity == 0 ? std::string("never")
                                             : num(s.min_reverse_velocity) + " .. " +
                                                   num(s.max_reverse_velocity) + " rpm"));
  line(out, "  acceleration " +
                (s.acceleration > 0 ? num(s.acceleration) + " rpm/s" : std::string("instant")) +
                ", at speed within " + num(s.at_speed_tolerance * 100) + " % in " +
                num(s.at_speed_timeout_s) + " s" + (s.stop_on_pause ? ", stops on pause" : ""));
  if (s.driver == SpindleDriver::gpio) {
    signal_line(out, "enable", s.enable);
    signal_line(out, "direction", s.direction);
    if (s.pwm.given()) {
      line(out, "  pwm = " + s.pwm.text + " at " + num(s.pwm_frequency) + " Hz, min duty " +
                    num(s.pwm_min_duty * 100) + " %");
    }
    signal_line(out, "encoder A", s.encoder_a);
    signal_line(out, "encoder B", s.encoder_b);
    signal_line(out, "encoder index", s.encoder_index);
    if (s.encoder_ppr > 0) line(out, "  encoder " + std::to_string(s.encoder_ppr) + " PPR");
  }
  if (s.driver == SpindleDriver::modbus) {
    line(out, "  MODBUS_" + std::to_string(s.modbus) + " slave " + std::to_string(s.slave) +
                  ", command hr " + std::to_string(s.command_register) + " (stop " +
                  std::to_string(s.command_stop) + ", forward " +
                  std::to_string(s.command_forward) + ", reverse " +
                  std::to_string(s.command_reverse) + "), speed hr " +
                  std::to_string(s.speed_register) + " x " + num(s.speed_scale));
    line(out, "  actual speed " +
                  (s.actual_speed_register < 0
                       ? std::string("none")
                       : std::string(table_name(s.actual_speed_table)) + " register " +
                             std::to_string(s.actual_speed_register)) +
                  ", status " +
                  (s.status_register < 0 ? std::string("none")
                                         : std::string(table_name(s.status_table)) + " register " +
                                               std::to_string(s.status_register) +
                                               " (running bit " + std::to_string(s.running_bit) +
                                               ", at speed bit " + std::to_string(s.at_speed_bit) +
                                               ", fault bit " + std::to_string(s.fault_bit) + ")"));
    if (s.position_register >= 0) {
      line(out,
           "  position " + std::string(table_name(s.position_table)) + " register " +
               std::to_string(s.position_register) + ", " + std::to_string(s.position_width) +
               " bits" +
               (s.position_width == 32
                    ? std::string(s.position_high_first ? ", high word first" : ", low word first")
                    : std::string()) +
               ", " + num(s.position_scale) + " counts/rev");
    }
  }
}

void describe_tool_change(std::string& out, const ToolChangeConfig& t) {
  std::string text;
  if (t.quill_up) text += "Z to machine zero, ";
  if (t.has_position) {
    text += "move to";
    for (std::size_t i = 0; i < t.position.size(); ++i) {
      if (t.position_given[i]) text += std::string(" ") + kAxisLetters[i] + num(t.position[i]);
    }
    text += ", ";
  }
  if (text.empty()) text = "where the machine stands, ";
  text += t.with_spindle_on ? "spindle keeps turning" : "spindle stopped";
  line(out, "Tool change:  " + text);
}

void describe_io(std::string& out, const IoConfig& io) {
  line(out, "I/O:");
  signal_line(out, "flood (M8)", io.flood);
  signal_line(out, "mist (M7)", io.mist);
  const auto numbered = [&](const char* name, const auto& signals) {
    for (std::size_t n = 0; n < signals.size(); ++n)
      signal_line(out, name + std::to_string(n), signals[n]);
  };
  numbered("digital output ", io.digital_outputs);
  numbered("analog output ", io.analog_outputs);
  numbered("digital input ", io.digital_inputs);
  numbered("analog input ", io.analog_inputs);
  for (const auto& dir : io.user_m_path)
    line(out, "  user M codes in " + dir.string());
  line(out, "  user M codes stopped after " + num(io.user_m_timeout_s) + " s");
}

// The panel's wiring by its INI keys, as the docs name them.
void describe_panel(std::string& out, const PanelConfig& p, const std::string& units) {
  if (!p.present) {
    line(out, "Panel:        none (no [PANEL])");
    return;
  }
  line(out, "Panel:        debounce " + std::to_string(p.debounce_ms) + " ms, door " +
                (p.door_mode == PanelConfig::DoorMode::estop
                     ? "trips the estop"
                     : "holds (feed hold, spindle stop at rest, coolant off)"));
  for (int i = 0; i < kPanelInputs; ++i) {
    signal_line(out, panel_input_key(static_cast<PanelInput>(i)),
                p.inputs[static_cast<std::size_t>(i)]);
  }
  const auto wiring = [](const PanelCounterWiring& w) {
    if (w.counts.given()) return "counter " + w.counts.text;
    return "encoder A " + w.a.text + ", B " + w.b.text;
  };
  if (p.mpg.given()) {
    line(out, "  MPG: " + wiring(p.mpg) + ", " + std::to_string(p.mpg_counts_per_detent) +
                  " counts a detent, " +
                  (p.mpg_mode == PanelConfig::MpgMode::velocity ? "velocity" : "position") +
                  " mode, steps " + num(p.mpg_step_distance[0]) + " / " +
                  num(p.mpg_step_distance[1]) + " / " + num(p.mpg_step_distance[2]) + " " + units +
                  (p.mpg_override_feed ? ", feed override while a program runs" : ""));
  } else {
    line(out, "  MPG: none");
  }
  static constexpr const char* kKnobs[] = {"feed", "rapid", "spindle"};
  for (std::size_t k = 0; k < p.knobs.size(); ++k) {
    const OverrideKnob& knob = p.knobs[k];
    if (knob.encoder.given()) {
      line(out, std::string("  ") + kKnobs[k] + " override knob: " + wiring(knob.encoder) + ", " +
                    num(knob.per_count * 100) + " % a count");
    } else if (knob.analog.given()) {
      line(out, std::string("  ") + kKnobs[k] + " override knob: analog " + knob.analog.text +
                    ", " + num(knob.analog_min) + " .. " + num(knob.analog_max) +
                    " over the override's range");
    }
  }
  for (int l = 0; l < kPanelLights; ++l) {
    signal_line(out, std::string(panel_light_key(static_cast<PanelLight>(l))),
                p.lights[static_cast<std::size_t>(l)]);
  }
}

}  // namespace

std::string describe(const MachineConfig& c) {
  std::string out;
  const std::string lu = linear_name(c.linear_units);
  const std::string au = angular_name(c.angular_units);
  line(out, "Machine:      " + or_none(c.machine_name));
  line(out, "File:         " + c.path.string());
  line(out, "Units:        linear " + lu + ", angular " + au);
  line(out, "Servo period: " + std::to_string(c.servo_period_ns) + " ns (" +
                num(1e9 / static_cast<double>(c.servo_period_ns)) + " Hz)");
  line(out, "Base period:  " +
                (c.base_period_ns > 0 ? std::to_string(c.base_period_ns) + " ns" : "none"));
  line(out, "Task cycle:   " + num(c.task_cycle_time_s) + " s");
  line(out, "Kinematics:   " + c.kinematics +
                (c.kinematics_args.empty() ? "" : " " + c.kinematics_args));
  line(out, "Coordinates:  " + c.coordinates + " (" + std::to_string(c.joint_count) + " joints" +
                (c.extra_joints > 0 ? ", " + std::to_string(c.extra_joints) + " extra" : "") + ")");
  line(out, "Trajectory:   max velocity " + num(c.max_linear_velocity) + " " + lu +
                "/s, max acceleration " + num(c.max_linear_acceleration) + " " + lu +
                "/s^2, default velocity " + num(c.default_linear_velocity) + " " + lu + "/s" +
                (c.scurve ? ", S-curve with max jerk " + num(c.max_linear_jerk) + " " + lu +
                                "/s^3 (trapezoids when an axis reaches its acceleration in "
                                "under 20 servo periods)"
                          : ", trapezoidal profiles"));
  line(out, "Homing:       " + std::string(c.no_force_homing ? "not required before programs"
                                                             : "required before programs"));
  line(out, "Feed override: up to " + num(c.max_feed_override * 100) + " %");
  line(out, "Spindle override: " + num(c.min_spindle_override * 100) + " to " +
                num(c.max_spindle_override * 100) + " %");
  line(out, "State files:  " + (c.cncd.state_dir.empty() ? std::string("none")
                                                         : c.cncd.state_dir.string() + " (" +
                                                               c.cncd.state_dir_origin + ")"));
  // Where a state file that is not there yet would start from.
  auto state_file = [&](const std::filesystem::path& file, const std::filesystem::path& seed) {
    std::error_code ec;
    if (file.empty() || std::filesystem::exists(file, ec)) return or_none(file);
    if (!seed.empty() && std::filesystem::exists(seed, ec)) {
      return file.string() + " (not there yet: starts as a copy of " + seed.string() + ")";
    }
    return file.string() + " (not there yet: starts from the defaults)";
  };
  line(out, "Parameters:   " + state_file(c.parameter_file, c.parameter_file_seed));
  line(out, "Tool table:   " + state_file(c.tool_table, c.tool_table_seed));
  line(out, "Positions:    " + state_file(c.position_file, c.position_file_seed));
  line(out, "Probe files:  " +
                (c.cncd.probe_dir.empty() ? std::string("none") : c.cncd.probe_dir.string()));
  if (!c.startup_code.empty()) line(out, "Startup code: " + c.startup_code);
  line(out, std::string("Dialect:      ") +
                (c.dialect == Dialect::numeryx ? "numeryx" : "linuxcnc") +
                " (a program's first line \"(dialect NAME)\" may name the other)");
  line(out, "Numeryx clearance: " +
                (c.numeryx_clearance ? num(*c.numeryx_clearance) + " " + lu
                                     : std::string("1 mm in G21 programs, 0.04 in in G20 ones")));
  line(out, std::string("Tapping:      G84/G74 ") +
                (c.rigid_tapping ? "rigid, in step with the spindle ([RS274NGC] RIGID_TAPPING)"
                                 : "with a floating holder, as LinuxCNC"));
  for (const auto& dir : c.subroutine_path)
    line(out, "Subroutines:  " + dir.string());
  for (const auto& dir : c.program_dirs)
    line(out, "Programs in:  " + dir.string());

  line(out, "Axes:");
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const AxisConfig& a = c.axes[i];
    if (!a.present) continue;
    const char letter = kAxisLetters[i];
    const std::string u = std::string_view("ABC").find(letter) != std::string_view::npos ? au : lu;
    line(out, std::string("  ") + letter + ": limits " + num(a.min_limit) + " .. " +
                  num(a.max_limit) + " " + u + ", max velocity " + num(a.max_velocity) + " " + u +
                  "/s, max acceleration " + num(a.max_acceleration) + " " + u + "/s^2" +
                  (a.max_jerk > 0 ? ", max jerk " + num(a.max_jerk) + " " + u + "/s^3" : ""));
  }
  line(out, "Joints:");
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    const JointConfig& j = c.joints[i];
    const bool angular = j.type == JointType::angular;
    const std::string u = angular ? au : lu;
    const bool motor = c.kinematics == "corexykins" && i < 2 &&
                       static_cast<int>(i) < c.joint_count - c.extra_joints;
    const std::string axis = motor            ? std::string(i == 0 ? "X + Y" : "X - Y") + " (motor)"
                             : j.axis == '\0' ? std::string("none (extra joint)")
                                              : std::string(1, j.axis);
    std::string home = "home " + num(j.home) + " " + u + ", ";
    if (j.home_search_vel == 0) {
      home += "homes where it stands";
    } else {
      home += "search " + num(j.home_search_vel) + " latch " + num(j.home_latch_vel) + " " + u +
              "/s, offset " + num(j.home_offset);
    }
    home += ", sequence " + (j.home_sequence < 0 ? std::string("none")
                                                 : (j.home_sequence_sync ? "-" : "") +
                                                       std::to_string(j.home_sequence));
    line(out, "  " + std::to_string(i) + ": axis " + axis + ", " +
                  (angular ? "angular" : "linear") + ", driver " + j.driver);
    line(out, "     limits " + num(j.min_limit) + " .. " + num(j.max_limit) + " " + u +
                  ", max velocity " + num(j.max_velocity) + " " + u + "/s, max acceleration " +
                  num(j.max_acceleration) + " " + u + "/s^2");
    line(out, "     ferror " + num(j.ferror) + " (standstill " + num(j.min_ferror) + ") " + u +
                  (j.backlash > 0 ? ", backlash " + num(j.backlash) : "") +
                  (j.scale != 0 ? ", scale " + num(j.scale) : ""));
    line(out, "     " + home);
  }
  describe_spindle(out, c.spindle);
  describe_tool_change(out, c.tool_change);
  describe_io(out, c.io);
  describe_panel(out, c.panel, lu);
  line(out, "cncd:");
  line(out, "  socket " + c.cncd.socket_path + ", read group " + or_none(c.cncd.read_group) +
                ", control group " + or_none(c.cncd.control_group));
  line(out, "  connections at most " + std::to_string(c.cncd.max_connections) + ", " +
                std::to_string(c.cncd.max_connections_per_user) + " per user, the last " +
                std::to_string(c.cncd.control_reserve) + " kept for control access");
  line(out, "  RT priority " + std::to_string(c.cncd.rt_priority) + ", RT CPU " +
                (c.cncd.rt_cpu < 0 ? std::string("any") : std::to_string(c.cncd.rt_cpu)) +
                ", log level " + c.cncd.log_level);
  return out;
}

}  // namespace cncd::config
