// GpioDriver::configure: lines, step timing and inputs from [GPIO] and [JOINT_n] (non-RT).
#include <algorithm>
#include <set>

#include "cncd/drivers/gpio_driver.hpp"
#include "ini_lookup.hpp"
#include "stepgen.hpp"

namespace cncd::drivers {

std::string GpioDriver::configure(const config::MachineConfig& machine,
                                  const std::vector<int>& joints) {
  if (joints.size() > static_cast<std::size_t>(kMaxJoints)) return "too many joints for one driver";
  if (!machine.ini) return "needs the machine's INI file for its [GPIO] settings";
  IniLookup ini(machine);
  base_period_ns_ = machine.base_period_ns;
  servo_period_ns_ = machine.servo_period_ns;
  rt_priority_ = machine.cncd.rt_priority;
  if (base_period_ns_ <= 0) {
    ini.fail("EMCMOT", "BASE_PERIOD", "step generation needs a base thread: set BASE_PERIOD");
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
  std::vector<int> input_lines;
  std::vector<std::pair<bool, int>> input_specs;  // active_low, line
  std::set<int> used;
  const auto line = [&](const std::string& section, const char* key, bool required) -> int {
    const auto spec = ini.text(section, key);
    if (!spec || spec->empty()) {
      if (required) ini.fail(section, key, "missing: a line offset or name");
      return -1;
    }
    std::string why;
    const int offset = backend_->find_line(*spec, why);
    if (offset < 0) {
      ini.fail(section, key, why);
      return -1;
    }
    if (!used.insert(offset).second) {
      ini.fail(section, key, "line " + *spec + " is already used by another signal");
      return -1;
    }
    return offset;
  };
  const auto add_input = [&](const std::string& section, const char* key,
                             const char* low_key) -> int {
    const int offset = line(section, key, false);
    if (offset < 0) return -1;
    input_lines.push_back(offset);
    input_specs.emplace_back(ini.boolean(section, low_key), offset);
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
    if (const int o = line(s, "ENABLE_LINE", false); o >= 0) {
      jl.enable_output = static_cast<int>(outputs.size());
      outputs.push_back(GpioOutput{o, prefix + "enable"});
    }
    jl.enable_active_low = ini.boolean(s, "ENABLE_ACTIVE_LOW");
    jl.home = add_input(s, "HOME_SWITCH_LINE", "HOME_SWITCH_ACTIVE_LOW");
    jl.min_limit = add_input(s, "MIN_LIMIT_LINE", "MIN_LIMIT_ACTIVE_LOW");
    jl.max_limit = add_input(s, "MAX_LIMIT_LINE", "MAX_LIMIT_ACTIVE_LOW");
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
  estop_input_ = add_input("GPIO", "ESTOP_LINE", "ESTOP_ACTIVE_LOW");
  probe_input_ = add_input("GPIO", "PROBE_LINE", "PROBE_ACTIVE_LOW");
  if (estop_input_ >= 0) capabilities_ |= kCapEstopInput;
  if (!ini.error().empty()) return ini.error();

  input_count_ = input_lines.size();
  inputs_ = std::make_unique<Input[]>(std::max<std::size_t>(1, input_count_));
  for (std::size_t i = 0; i < input_count_; ++i) {
    inputs_[i].backend_index = static_cast<int>(i);
    inputs_[i].active_low = input_specs[i].first;
    inputs_[i].debounce_ticks = debounce_ticks;
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
