// GpioDriver::configure: lines, step timing and inputs from [GPIO] and [JOINT_n], signals
// and the spindle from their addresses (non-RT).
#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

#include "cncd/drivers/gpio_driver.hpp"
#include "ini_lookup.hpp"
#include "panel_wiring.hpp"
#include "pwm_encoder.hpp"
#include "stepgen.hpp"

namespace cncd::drivers {
namespace {

// "FILE:LINE: ADDRESS: " for a problem with a signal address.
std::string where(const config::SignalAddress& a) {
  std::string out;
  if (!a.source.file.empty()) out = a.source.file + ":" + std::to_string(a.source.line) + ": ";
  return out + (a.text.empty() ? "gpio:" + a.line : a.text) + ": ";
}

bool is_gpio(const config::SignalAddress& a) {
  return a.kind == config::SignalAddress::Kind::gpio;
}

}  // namespace

std::string GpioDriver::configure_io(const config::MachineConfig& machine,
                                     std::vector<GpioOutput>& outputs,
                                     std::vector<GpioLine>& input_lines,
                                     std::vector<std::pair<bool, int>>& input_specs,
                                     std::set<int>& used) {
  std::string problem;
  encoder_a_ = encoder_b_ = encoder_index_ = -1;
  pwmgen_.reset();
  encoder_.reset();
  const auto claim = [&](const config::SignalAddress& a) -> int {
    std::string why;
    const int offset = backend_->find_line(a.line, why);
    if (offset < 0) {
      if (problem.empty()) problem = where(a) + why;
      return -1;
    }
    if (!used.insert(offset).second) {
      if (problem.empty())
        problem = where(a) + "line " + a.line + " is already used by another signal";
      return -1;
    }
    return offset;
  };
  const auto output = [&](const config::SignalAddress& a, const std::string& name) {
    OutputLine out;
    if (!is_gpio(a)) return out;
    if (const int offset = claim(a); offset >= 0) {
      out.output = static_cast<int>(outputs.size());
      out.active_low = a.active_low;
      outputs.push_back(GpioOutput{offset, name});
    }
    return out;
  };
  // Raw input levels (the encoder) and debounced ones (digital inputs) both come from here.
  const auto input = [&](const config::SignalAddress& a, const std::string& name) -> int {
    if (!is_gpio(a)) return -1;
    const int offset = claim(a);
    if (offset < 0) return -1;
    input_lines.push_back(GpioLine{offset, name});
    input_specs.emplace_back(a.active_low, offset);
    return static_cast<int>(input_lines.size()) - 1;
  };
  const config::IoConfig& io = machine.io;
  flood_ = output(io.flood, "flood");
  mist_ = output(io.mist, "mist");
  for (std::size_t n = 0; n < digital_out_.size(); ++n)
    digital_out_[n] = output(io.digital_outputs[n], "dout" + std::to_string(n));
  for (std::size_t n = 0; n < digital_in_.size(); ++n)
    digital_in_[n] = input(io.digital_inputs[n], "din" + std::to_string(n));
  for (const auto* analog : {&io.analog_outputs, &io.analog_inputs}) {
    for (const auto& a : *analog) {
      if (is_gpio(a) && problem.empty()) {
        problem = where(a) + "a GPIO line carries no analog value (use modbus:BUS:SLAVE:hr:N)";
      }
    }
  }

  if (auto why = configure_panel(machine, input, output); !why.empty() && problem.empty()) {
    problem = why;
  }

  const config::SpindleConfig& sp = machine.spindle;
  spindle_ = sp.present && sp.driver == config::SpindleDriver::gpio;
  if (!spindle_) return problem;
  const std::string section = "[SPINDLE_0] ";
  spindle_enable_ = output(sp.enable, "spindle_enable");
  spindle_dir_ = output(sp.direction, "spindle_dir");
  spindle_pwm_ = output(sp.pwm, "spindle_pwm");
  spindle_max_rpm_ = sp.max_forward_velocity;
  pwm_min_duty_ = sp.pwm_min_duty;
  spindle_acceleration_ = sp.acceleration;
  if (sp.acceleration < 0 && problem.empty()) {
    problem = section + "ACCELERATION must not be negative (0 = at once)";
  }
  if (sp.pwm.given()) {
    const double base_rate = 1e9 / static_cast<double>(base_period_ns_);
    if (!(sp.max_forward_velocity > 0 && sp.max_forward_velocity < 1e9) && problem.empty()) {
      problem = section + "PWM needs MAX_FORWARD_VELOCITY, the speed at full duty";
    }
    if (!(sp.pwm_min_duty >= 0 && sp.pwm_min_duty < 1) && problem.empty()) {
      problem = section + "PWM_MIN_DUTY must be at least 0 and below 1";
    }
    if (!(sp.pwm_frequency > 0 && sp.pwm_frequency * 2 <= base_rate) && problem.empty()) {
      problem = section + "PWM_FREQUENCY must be positive and at most half the base rate (" +
                std::to_string(static_cast<long>(base_rate / 2)) + " Hz at BASE_PERIOD " +
                std::to_string(base_period_ns_) + ")";
    }
    pwmgen_ = std::make_unique<Pwmgen>();
    pwmgen_->setup(base_rate / sp.pwm_frequency);
  }
  if (sp.encoder_a.given() || sp.encoder_b.given() || sp.encoder_ppr > 0) {
    if ((!is_gpio(sp.encoder_a) || !is_gpio(sp.encoder_b) || sp.encoder_ppr <= 0) &&
        problem.empty()) {
      problem = section + "an encoder needs ENCODER_A and ENCODER_B on gpio lines and ENCODER_PPR";
    }
    encoder_a_ = input(sp.encoder_a, "spindle_a");
    encoder_b_ = input(sp.encoder_b, "spindle_b");
    encoder_index_ = input(sp.encoder_index, "spindle_index");
    encoder_ = std::make_unique<QuadratureDecoder>();
    encoder_->setup(4 * std::max(1, sp.encoder_ppr));
  }
  return problem;
}

std::string GpioDriver::configure_panel(
    const config::MachineConfig& machine,
    const std::function<int(const config::SignalAddress&, const std::string&)>& input,
    const std::function<OutputLine(const config::SignalAddress&, const std::string&)>& output) {
  std::string problem;
  const auto note = [&](const std::string& why) {
    if (problem.empty()) problem = why;
  };
  const config::PanelConfig& panel = machine.panel;
  for (std::size_t i = 0; i < panel_in_.size(); ++i) {
    const auto which = static_cast<config::PanelInput>(i);
    panel_in_[i] = input(panel.inputs[i], panel_signal_name(config::panel_input_key(which)));
  }
  for (int c = 0; c < config::kPanelCounters; ++c) {
    const auto k = static_cast<std::size_t>(c);
    PanelEncoder& encoder = panel_encoders_[k];
    encoder = PanelEncoder{};
    panel_counts_[k].store(0);
    panel_errors_[k].store(0);
    const config::PanelCounterWiring& w = panel_counter_wiring(panel, c);
    const std::string key = panel_counter_key(c);
    if (is_gpio(w.counts)) {
      note(where(w.counts) + "a GPIO line carries no count: wire the encoder to " + key +
           "_A and " + key + "_B");
    }
    if (!is_gpio(w.a) && !is_gpio(w.b)) continue;
    if (!is_gpio(w.a) || !is_gpio(w.b)) {
      note("[PANEL] " + key + "_A and " + key + "_B: an encoder on GPIO needs both on gpio lines");
      continue;
    }
    encoder.a = input(w.a, panel_signal_name(key + "_A"));
    encoder.b = input(w.b, panel_signal_name(key + "_B"));
    encoder.a_low = w.a.active_low;
    encoder.b_low = w.b.active_low;
    if (encoder.a < 0 || encoder.b < 0) encoder.a = encoder.b = -1;  // a line was refused
  }
  for (int k = 0; k < config::kPanelAnalogs; ++k) {
    const config::SignalAddress& a = panel_analog_address(panel, k);
    if (is_gpio(a)) {
      note(where(a) +
           "a GPIO line carries no analog value (use modbus:BUS:SLAVE:ir:N or sim:NAME)");
    }
  }
  for (std::size_t l = 0; l < panel_light_.size(); ++l) {
    const auto which = static_cast<config::PanelLight>(l);
    panel_light_[l] =
        output(panel.lights[l], panel_signal_name(std::string(config::panel_light_key(which))));
  }
  return problem;
}

std::string GpioDriver::configure(const config::MachineConfig& machine,
                                  const std::vector<int>& joints) {
  if (joints.size() > static_cast<std::size_t>(kMaxJoints)) return "too many joints for one driver";
  if (!machine.ini) return "needs the machine's INI file for its [GPIO] settings";
  IniLookup ini(machine);
  base_period_ns_ = machine.base_period_ns;
  servo_period_ns_ = machine.servo_period_ns;
  // A base period longer than the servo period is silent for a few servo periods by design.
  stale_reads_ = kStaleServoPeriods *
                 std::max<std::int64_t>(1, (base_period_ns_ + servo_period_ns_ - 1) /
                                               std::max<std::int64_t>(1, servo_period_ns_));
  rt_priority_ = machine.cncd.rt_priority;
  if (base_period_ns_ <= 0) {
    // The base thread generates steps, samples the lines and decodes the panel's encoders.
    ini.fail("EMCMOT", "BASE_PERIOD",
             "the gpio driver needs a base thread (steps, inputs, encoders): set BASE_PERIOD");
    return ini.error();
  }
  const auto chip = ini.text("GPIO", "CHIP");
  if (!chip || chip->empty()) {
    ini.fail("GPIO", "CHIP", "missing: name the GPIO chip (gpiochip0) or vcd:FILE to record");
    return ini.error();
  }
  std::string error;
  backend_ = make_gpio_backend(*chip, error);
  if (!backend_) {
    ini.fail("GPIO", "CHIP", error);
    return ini.error();
  }
  const std::int64_t debounce_ns = ini.integer("GPIO", "DEBOUNCE_NS");
  const int debounce_ticks = ticks_for(debounce_ns, base_period_ns_);

  std::vector<GpioOutput> outputs;
  std::vector<GpioLine> input_lines;
  std::vector<std::pair<bool, int>> input_specs;  // active_low, line
  std::set<int> used;
  // The line a key names; `active_low` gets its polarity (a '!' or the key's *_ACTIVE_LOW).
  const auto line = [&](const std::string& section, const char* key, bool required,
                        bool* active_low = nullptr) -> int {
    const std::string low_key = config::line_active_low_key(key);
    std::optional<bool> low;
    if (!low_key.empty() && ini.has(section, low_key)) low = ini.boolean(section, low_key);
    config::GpioLineKey spec;
    std::string why =
        config::parse_gpio_line_key(key, ini.text(section, key).value_or(""), low, spec);
    if (!why.empty()) {
      ini.fail(section, key, why);
      return -1;
    }
    if (spec.line.empty()) {
      if (required) ini.fail(section, key, "missing: a line offset or name");
      return -1;
    }
    const int offset = backend_->find_line(spec.line, why);
    if (offset < 0) {
      ini.fail(section, key, why);
      return -1;
    }
    if (!used.insert(offset).second) {
      ini.fail(section, key, "line " + spec.line + " is already used by another signal");
      return -1;
    }
    if (active_low != nullptr) *active_low = spec.active_low;
    return offset;
  };
  const auto add_input = [&](const std::string& section, const char* key,
                             const std::string& name) -> int {
    bool active_low = false;
    const int offset = line(section, key, false, &active_low);
    if (offset < 0) return -1;
    input_lines.push_back(GpioLine{offset, name});
    input_specs.emplace_back(active_low, offset);
    return static_cast<int>(input_lines.size()) - 1;
  };

  const double base_s = static_cast<double>(base_period_ns_) * 1e-9;
  joints_.assign(joints.size(), JointLines{});
  stepgens_.assign(joints.size(), Stepgen{});
  primed_.assign(joints.size(), false);
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const int j = joints[k];
    const std::string s = joint_section(j);
    const std::string prefix = "j" + std::to_string(j) + "_";
    JointLines& jl = joints_[k];
    jl.scale = machine.joints[static_cast<std::size_t>(j)].scale;
    if (jl.scale == 0) ini.fail(s, "SCALE", "step/dir joints need SCALE (steps per unit), not 0");
    if (const int o = line(s, "STEP_LINE", true); o >= 0) {
      jl.step_output = static_cast<int>(outputs.size());
      outputs.push_back(GpioOutput{o, prefix + "step"});
    }
    if (const int o = line(s, "DIR_LINE", true); o >= 0) {
      jl.dir_output = static_cast<int>(outputs.size());
      outputs.push_back(GpioOutput{o, prefix + "dir"});
    }
    if (const int o = line(s, "ENABLE_LINE", false, &jl.enable_active_low); o >= 0) {
      jl.enable_output = static_cast<int>(outputs.size());
      outputs.push_back(GpioOutput{o, prefix + "enable"});
    }
    jl.home = add_input(s, "HOME_SWITCH_LINE", prefix + "home");
    jl.min_limit = add_input(s, "MIN_LIMIT_LINE", prefix + "min_limit");
    jl.max_limit = add_input(s, "MAX_LIMIT_LINE", prefix + "max_limit");
    if (jl.home >= 0) capabilities_ |= kCapHomeSwitch;
    if (jl.min_limit >= 0 || jl.max_limit >= 0) capabilities_ |= kCapLimitSwitches;

    StepgenTiming t;
    t.base_period_s = base_s;
    t.servo_period_s = static_cast<double>(servo_period_ns_) * 1e-9;
    t.steplen_ticks = ticks_for(ini.integer(s, "STEPLEN"), base_period_ns_);
    t.stepspace_ticks = ticks_for(ini.integer(s, "STEPSPACE"), base_period_ns_);
    t.dirsetup_ticks = ticks_for(ini.integer(s, "DIRSETUP"), base_period_ns_);
    t.dirhold_ticks = ticks_for(ini.integer(s, "DIRHOLD"), base_period_ns_);
    const double scale = std::abs(jl.scale);
    t.max_velocity_steps = ini.real(s, "STEPGEN_MAXVEL") * scale;
    t.max_acceleration_steps = ini.real(s, "STEPGEN_MAXACCEL") * scale;
    stepgens_[k].setup(t);
  }
  estop_input_ = add_input("GPIO", "ESTOP_LINE", "estop");
  probe_input_ = add_input("GPIO", "PROBE_LINE", "probe");
  const config::SignalAddress& probe = machine.io.probe_input;
  if (probe_input_ < 0 && probe.kind == config::SignalAddress::Kind::gpio) {
    std::string why;
    const int offset = backend_->find_line(probe.line, why);
    if (offset < 0) return where(probe) + why;
    if (!used.insert(offset).second) {
      return where(probe) + "line " + probe.line + " is already used by another signal";
    }
    input_lines.push_back(GpioLine{offset, "probe"});
    input_specs.emplace_back(probe.active_low, offset);
    probe_input_ = static_cast<int>(input_lines.size()) - 1;
  }
  if (estop_input_ >= 0) capabilities_ |= kCapEstopInput;
  if (!ini.error().empty()) return ini.error();
  if (auto problem = configure_io(machine, outputs, input_lines, input_specs, used);
      !problem.empty()) {
    return problem;
  }

  input_count_ = input_lines.size();
  inputs_ = std::make_unique<Input[]>(std::max<std::size_t>(1, input_count_));
  for (std::size_t i = 0; i < input_count_; ++i) {
    inputs_[i].backend_index = static_cast<int>(i);
    inputs_[i].active_low = input_specs[i].first;
    inputs_[i].debounce_ticks = debounce_ticks;
  }
  // The panel's buttons are read as sampled: the servo thread debounces them ([PANEL]
  // DEBOUNCE_MS).
  for (const int index : panel_in_) {
    if (index >= 0) inputs_[static_cast<std::size_t>(index)].debounce_ticks = 1;
  }
  output_levels_.assign(outputs.size(), 0);
  input_levels_.assign(input_count_, 0);
  if (auto problem = backend_->request(outputs, input_lines); !problem.empty()) {
    ini.fail("GPIO", "CHIP", problem);
    return ini.error();
  }
  return "";
}

}  // namespace cncd::drivers
