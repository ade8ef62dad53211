// Cross-checks of the spindle, the [CNCD] signals and the tool change: what a driver needs,
// which way each address can carry a signal, the buses and lines they name, and no output
// driven from two places.
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

constexpr std::string_view kSpindle = "SPINDLE_0";

// One signal a key names, for the checks that look at all of them.
struct Signal {
  std::string section;
  std::string key;
  const SignalAddress* address;
  SignalUse use;
};

bool is_output(SignalUse use) {
  return use == SignalUse::digital_output || use == SignalUse::analog_output;
}

std::string label(std::string_view section, std::string_view key) {
  return "[" + std::string(section) + "] " + std::string(key);
}

std::string at_line(const SourceRef& ref) {
  return ref.file + ":" + std::to_string(ref.line);
}

// What one physical signal is, whatever its polarity: two keys with the same identity drive
// or read the same line, coil or register.
std::string identity(const SignalAddress& a) {
  switch (a.kind) {
    case SignalAddress::Kind::gpio:
      return "gpio line " + a.line;
    case SignalAddress::Kind::modbus: {
      static constexpr const char* kTables[] = {"coil", "holding register", "discrete input",
                                                "input register"};
      return "modbus bus " + std::to_string(a.bus) + " slave " + std::to_string(a.slave) + " " +
             kTables[static_cast<int>(a.table)] + " " + std::to_string(a.address);
    }
    case SignalAddress::Kind::sim:
      return "sim signal " + a.name;
    case SignalAddress::Kind::evdev:
      return "input device " + a.device + " " + a.code;
    case SignalAddress::Kind::none:
      break;
  }
  return "";
}

std::vector<Signal> program_signals(const IoConfig& io) {
  std::vector<Signal> out;
  const auto add = [&](std::string key, const SignalAddress& a, SignalUse use) {
    if (a.given()) out.push_back(Signal{"CNCD", std::move(key), &a, use});
  };
  add("FLOOD_OUTPUT", io.flood, SignalUse::digital_output);
  add("MIST_OUTPUT", io.mist, SignalUse::digital_output);
  for (std::size_t n = 0; n < io.digital_outputs.size(); ++n)
    add("DIGITAL_OUTPUT_" + std::to_string(n), io.digital_outputs[n], SignalUse::digital_output);
  for (std::size_t n = 0; n < io.analog_outputs.size(); ++n)
    add("ANALOG_OUTPUT_" + std::to_string(n), io.analog_outputs[n], SignalUse::analog_output);
  for (std::size_t n = 0; n < io.digital_inputs.size(); ++n)
    add("DIGITAL_INPUT_" + std::to_string(n), io.digital_inputs[n], SignalUse::digital_input);
  for (std::size_t n = 0; n < io.analog_inputs.size(); ++n)
    add("ANALOG_INPUT_" + std::to_string(n), io.analog_inputs[n], SignalUse::analog_input);
  add("PROBE_INPUT", io.probe_input, SignalUse::digital_input);
  return out;
}

std::vector<Signal> spindle_signals(const SpindleConfig& s) {
  std::vector<Signal> out;
  const auto add = [&](std::string key, const SignalAddress& a, SignalUse use) {
    if (a.given()) out.push_back(Signal{std::string(kSpindle), std::move(key), &a, use});
  };
  add("ENABLE", s.enable, SignalUse::digital_output);
  add("DIRECTION", s.direction, SignalUse::digital_output);
  add("PWM", s.pwm, SignalUse::digital_output);
  add("ENCODER_A", s.encoder_a, SignalUse::digital_input);
  add("ENCODER_B", s.encoder_b, SignalUse::digital_input);
  add("ENCODER_INDEX", s.encoder_index, SignalUse::digital_input);
  return out;
}

bool has_chip(TypedReader& r) {
  const auto chip = r.ini().value("GPIO", "CHIP");
  return chip && !trim(strip_trailing_comment(*chip)).empty();
}

void check_speeds(TypedReader& r, const SpindleConfig& s) {
  const auto failed = [&](const char* a, const char* b) {
    return r.failed(kSpindle, a) || r.failed(kSpindle, b);
  };
  if (s.min_forward_velocity > s.max_forward_velocity &&
      !failed("MIN_FORWARD_VELOCITY", "MAX_FORWARD_VELOCITY")) {
    r.problem(kSpindle, "MIN_FORWARD_VELOCITY",
              format_number(s.min_forward_velocity) + " must not be above MAX_FORWARD_VELOCITY " +
                  format_number(s.max_forward_velocity));
  }
  if (s.max_reverse_velocity > 0 && s.min_reverse_velocity > s.max_reverse_velocity &&
      !failed("MIN_REVERSE_VELOCITY", "MAX_REVERSE_VELOCITY") &&
      !failed("MIN_FORWARD_VELOCITY", "MAX_FORWARD_VELOCITY")) {
    const bool min_given = r.given(kSpindle, "MIN_REVERSE_VELOCITY");
    r.problem(kSpindle, min_given ? "MIN_REVERSE_VELOCITY" : "MAX_REVERSE_VELOCITY",
              "MIN_REVERSE_VELOCITY " + format_number(s.min_reverse_velocity) +
                  (min_given ? "" : " (from MIN_FORWARD_VELOCITY)") +
                  " must not be above MAX_REVERSE_VELOCITY " +
                  format_number(s.max_reverse_velocity));
  }
}

void check_gpio_spindle(TypedReader& r, const MachineConfig& c) {
  const SpindleConfig& s = c.spindle;
  if (!s.enable.given() && !s.pwm.given() && !r.failed(kSpindle, "ENABLE") &&
      !r.failed(kSpindle, "PWM")) {
    r.problem(kSpindle, "DRIVER", "DRIVER = gpio needs ENABLE or PWM (a gpio line)");
  }
  if (!has_chip(r)) {
    r.problem(kSpindle, "DRIVER", "DRIVER = gpio needs [GPIO] CHIP (gpiochip0, or vcd:FILE)");
  }
  for (const Signal& signal : spindle_signals(s)) {
    if (signal.address->kind == SignalAddress::Kind::modbus ||
        signal.address->kind == SignalAddress::Kind::evdev) {
      r.problem(kSpindle, signal.key,
                "'" + signal.address->text +
                    "': DRIVER = gpio drives gpio lines; write gpio:LINE (or sim:NAME)");
    }
  }
  if (s.pwm.given() && s.max_forward_velocity >= 1e99 &&
      !r.failed(kSpindle, "MAX_FORWARD_VELOCITY")) {
    r.problem(kSpindle, "PWM", "PWM needs MAX_FORWARD_VELOCITY, the speed at full duty cycle");
  }
  const bool fast =
      s.pwm.kind == SignalAddress::Kind::gpio || s.encoder_a.kind == SignalAddress::Kind::gpio;
  if (fast && c.base_period_ns <= 0 && !r.failed("EMCMOT", "BASE_PERIOD")) {
    r.problem(kSpindle, s.pwm.kind == SignalAddress::Kind::gpio ? "PWM" : "ENCODER_A",
              "a gpio PWM output or encoder needs a base thread: set [EMCMOT] BASE_PERIOD");
  }
  if (s.encoder_a.given() != s.encoder_b.given()) {
    const char* given = s.encoder_a.given() ? "ENCODER_A" : "ENCODER_B";
    r.problem(kSpindle, given,
              std::string(given) + " needs " + (s.encoder_a.given() ? "ENCODER_B" : "ENCODER_A") +
                  ": the encoder has two channels");
  } else if (s.encoder_a.given() && s.encoder_ppr <= 0 && !r.failed(kSpindle, "ENCODER_PPR")) {
    r.problem(kSpindle, r.given(kSpindle, "ENCODER_PPR") ? "ENCODER_PPR" : "ENCODER_A",
              "ENCODER_A and ENCODER_B need ENCODER_PPR (pulses per revolution) above 0");
  }
  if (s.encoder_index.given() && !s.encoder_a.given() && !s.encoder_b.given()) {
    r.problem(kSpindle, "ENCODER_INDEX", "ENCODER_INDEX needs ENCODER_A and ENCODER_B");
  }
}

// The position counter of a servo spindle or VFD: it is unwrapped between readings, so a
// revolution must be well under half its range.
void check_spindle_position(TypedReader& r, const SpindleConfig& s) {
  if (s.position_register < 0) {
    for (const char* key : {"POSITION_TABLE", "POSITION_WIDTH", "WORD_ORDER", "POSITION_SCALE"}) {
      if (r.given(kSpindle, key) && !r.failed(kSpindle, "POSITION_REGISTER")) {
        r.warning(kSpindle, key, "ignored: no POSITION_REGISTER");
      }
    }
    return;
  }
  // The position is estimated between readings, and the spindle's commands wait for the bus:
  // a slow bus leaves a rigid tap off its helix (docs/motion.md).
  if (s.modbus >= 0) {
    const std::string bus = "MODBUS_" + std::to_string(s.modbus);
    const auto period = r.ini().value(bus, "UPDATE_PERIOD_MS");
    char* end = nullptr;
    const long ms = period ? std::strtol(period->c_str(), &end, 10) : 10;
    if (period && end != period->c_str() && *end == '\0' && ms > 10) {
      r.warning(kSpindle, "POSITION_REGISTER",
                "[" + bus + "] UPDATE_PERIOD_MS = " + std::to_string(ms) +
                    ": a rigid tap on a spindle read that seldom may be off its helix by more "
                    "than pitch x 0.02; keep it at 10 or less");
    }
  }
  if (s.position_width == 32 && s.position_register > 65534) {
    r.problem(kSpindle, "POSITION_REGISTER",
              "a 32-bit position takes two registers: at most 65534");
  }
  if (r.failed(kSpindle, "POSITION_SCALE")) return;
  if (!r.given(kSpindle, "POSITION_SCALE")) {
    r.problem(kSpindle, "POSITION_REGISTER",
              "POSITION_REGISTER needs POSITION_SCALE, the position counts a revolution");
  } else if (s.position_scale == 0) {
    r.problem(kSpindle, "POSITION_SCALE", "must not be 0 (counts a revolution)");
  } else if (std::fabs(s.position_scale) > std::ldexp(1.0, s.position_width - 2)) {
    r.problem(kSpindle, "POSITION_SCALE",
              "a " + std::to_string(s.position_width) + "-bit counter wraps every " +
                  std::to_string(1LL << s.position_width) +
                  " counts: a revolution must be at most a quarter of that (" +
                  std::to_string(1LL << (s.position_width - 2)) + ")");
  }
}

void check_modbus_spindle(TypedReader& r, const SpindleConfig& s) {
  if (!r.given(kSpindle, "MODBUS")) {
    r.problem(kSpindle, "DRIVER", "DRIVER = modbus needs MODBUS = n naming a [MODBUS_n] section");
  } else if (s.modbus >= 0 && !r.ini().has_section("MODBUS_" + std::to_string(s.modbus))) {
    r.problem(kSpindle, "MODBUS",
              "no section [MODBUS_" + std::to_string(s.modbus) + "] in the file");
  }
  if (s.command_register == s.speed_register && !r.failed(kSpindle, "COMMAND_REGISTER") &&
      !r.failed(kSpindle, "SPEED_REGISTER")) {
    r.problem(kSpindle, r.given(kSpindle, "SPEED_REGISTER") ? "SPEED_REGISTER" : "COMMAND_REGISTER",
              "COMMAND_REGISTER and SPEED_REGISTER are both holding register " +
                  std::to_string(s.speed_register));
  }
  check_spindle_position(r, s);
}

// A line of the joints and [GPIO] ("[JOINT_0] STEP_LINE") and whether cncd drives it.
struct Taken {
  std::string label;
  SourceRef source;
  bool output = false;
  bool panel = false;
};

void reserve_gpio_lines(TypedReader& r, const MachineConfig& c,
                        std::map<std::string, Taken>& taken) {
  const auto reserve = [&](const std::string& section, const char* key, bool output) {
    const auto line = r.gpio_line(section, key);
    if (line && !line->line.empty()) {
      taken.emplace("gpio line " + line->line,
                    Taken{label(section, key), r.where(section, key), output});
    }
  };
  if (r.ini().has_section("GPIO")) {
    reserve("GPIO", "ESTOP_LINE", false);
    reserve("GPIO", "PROBE_LINE", false);
  }
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    if (c.joints[i].driver != "gpio") continue;
    const std::string s = "JOINT_" + std::to_string(i);
    for (const char* key : {"STEP_LINE", "DIR_LINE", "ENABLE_LINE"})
      reserve(s, key, true);
    for (const char* key : {"HOME_SWITCH_LINE", "MIN_LIMIT_LINE", "MAX_LIMIT_LINE"})
      reserve(s, key, false);
  }
}

// Two keys on one output fight over it; an output on a line read as an input breaks the input.
void check_shared(TypedReader& r, const MachineConfig& c, const std::vector<Signal>& signals) {
  std::map<std::string, Taken> taken;
  reserve_gpio_lines(r, c, taken);
  for (const bool outputs : {true, false}) {
    for (const Signal& s : signals) {
      if (is_output(s.use) != outputs) continue;
      const std::string id = identity(*s.address);
      const bool panel = s.section == "PANEL";
      const auto [it, fresh] =
          taken.emplace(id, Taken{label(s.section, s.key), s.address->source, outputs, panel});
      if (fresh) continue;
      const Taken& other = it->second;
      const bool gpio = s.address->kind == SignalAddress::Kind::gpio;
      // Reading back a coil or a sim signal one writes is fine; a gpio line is one or the other.
      // A panel input is one button: two panel keys on it, or a gpio line the driver reads for
      // another key too, is a wiring mistake.
      const bool both_inputs_clash =
          !other.output && (panel || other.panel) && (gpio || (panel && other.panel));
      if (!outputs && !both_inputs_clash && (!other.output || !gpio)) continue;
      const std::string why =
          outputs        ? (other.output ? "; an output has one driver"
                                         : ", an input; an output cannot share its line")
          : other.output ? ", an output; an input cannot share its line"
                         : ", an input too; a panel input has a signal of its own";
      r.problem(s.section, s.key,
                "'" + s.address->text + "': " + id + " is also " + other.label +
                    (other.source.line > 0 ? " (" + at_line(other.source) + ")" : "") + why);
    }
  }
}

// The gpio driver reads the panel's lines (and decodes its encoders) in the base thread.
void check_panel_base_thread(TypedReader& r, const MachineConfig& c,
                             const std::vector<Signal>& signals) {
  if (c.base_period_ns > 0 || r.failed("EMCMOT", "BASE_PERIOD")) return;
  for (const Signal& s : signals) {
    if (s.section == "PANEL" && s.address->kind == SignalAddress::Kind::gpio) {
      r.problem(s.section, s.key,
                "'" + s.address->text +
                    "': the panel's gpio lines are read in the base thread: set [EMCMOT] "
                    "BASE_PERIOD");
      return;
    }
  }
}

void check_signals(TypedReader& r, const MachineConfig& c) {
  std::vector<Signal> signals = program_signals(c.io);
  for (const PanelSignal& s : panel_signals(c.panel))
    signals.push_back(Signal{"PANEL", s.key, s.address, s.use});
  check_panel_base_thread(r, c, signals);
  const bool check_chip = !has_chip(r);
  for (const Signal& s : signals) {
    const SignalAddress& a = *s.address;
    if (const std::string why = signal_use_refusal(a, s.use); !why.empty()) {
      r.problem(s.section, s.key, "'" + a.text + "': " + why);
    }
    if (a.kind == SignalAddress::Kind::modbus &&
        !r.ini().has_section("MODBUS_" + std::to_string(a.bus))) {
      r.problem(s.section, s.key,
                "'" + a.text + "': no section [MODBUS_" + std::to_string(a.bus) + "] in the file");
    }
    if (a.kind == SignalAddress::Kind::gpio && check_chip) {
      r.problem(s.section, s.key, "'" + a.text + "': a gpio line needs [GPIO] CHIP");
    }
  }
  if (c.spindle.driver == SpindleDriver::gpio) {
    for (const Signal& s : spindle_signals(c.spindle))
      signals.push_back(s);
  }
  check_shared(r, c, signals);
}

void check_tool_change(TypedReader& r, const MachineConfig& c) {
  const ToolChangeConfig& t = c.tool_change;
  const auto outside = [&](std::size_t i, double position, const char* key,
                           const std::string& what) {
    const AxisConfig& axis = c.axes[i];
    const std::string s = std::string("AXIS_") + kAxisLetters[i];
    if (!axis.present || r.failed(s, "MIN_LIMIT") || r.failed(s, "MAX_LIMIT")) return;
    const bool below = position < axis.min_limit;
    if (!below && position <= axis.max_limit) return;
    r.problem("EMCIO", key,
              what + " is " +
                  (below ? "below [" + s + "] MIN_LIMIT " : "above [" + s + "] MAX_LIMIT ") +
                  format_number(below ? axis.min_limit : axis.max_limit) +
                  ": the tool change would leave the soft limits");
  };
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    if (t.position_given[i]) {
      outside(i, t.position[i], "TOOL_CHANGE_POSITION",
              std::string(1, kAxisLetters[i]) + " " + format_number(t.position[i]));
    }
  }
  if (t.quill_up) outside(2, 0, "TOOL_CHANGE_QUILL_UP", "Z 0 (machine zero)");
  // Run from line: the height the tool rises to must be one the machine can reach.
  const AxisConfig& z = c.axes[2];
  if (const auto safe = c.cncd.run_from_line_safe_z;
      safe && z.present && !r.failed("AXIS_Z", "MIN_LIMIT") && !r.failed("AXIS_Z", "MAX_LIMIT") &&
      (*safe < z.min_limit || *safe > z.max_limit)) {
    r.problem("CNCD", "RUN_FROM_LINE_SAFE_Z",
              format_number(*safe) + " is outside [AXIS_Z] MIN_LIMIT " +
                  format_number(z.min_limit) + " to MAX_LIMIT " + format_number(z.max_limit) +
                  ": a run from a line could not rise to it");
  }
}

}  // namespace

// The probe must stop the machine in the servo period of contact: a Modbus input arrives an
// update period or more late, a gpio line is read in the base thread.
void check_probe(TypedReader& r, const MachineConfig& c) {
  const SignalAddress& a = c.io.probe_input;
  if (a.kind == SignalAddress::Kind::modbus) {
    r.problem("CNCD", "PROBE_INPUT",
              "'" + a.text +
                  "': a Modbus input answers an update period (UPDATE_PERIOD_MS) or more late, "
                  "too late to stop a probe on contact: wire the probe to a gpio line");
  }
  if (a.given() && r.given("GPIO", "PROBE_LINE")) {
    r.problem("CNCD", "PROBE_INPUT", "give the probe once: [GPIO] PROBE_LINE is given too");
  }
}

void validate_io(TypedReader& r, const MachineConfig& c) {
  const SpindleConfig& s = c.spindle;
  check_probe(r, c);
  check_speeds(r, s);
  if (s.driver == SpindleDriver::gpio) check_gpio_spindle(r, c);
  if (s.driver == SpindleDriver::modbus) check_modbus_spindle(r, s);
  check_signals(r, c);
  check_tool_change(r, c);
}

}  // namespace cncd::config
