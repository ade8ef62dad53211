#include "cncd/pipeline/machine.hpp"

#include <memory>
#include <string>

#include "cncd/config/ini_file.hpp"

namespace cncd::pipeline {

// The interpreter checks program I/O indexes against the signals the machine can have.
static_assert(interp::kDigitalIoCount == config::kMaxDigitalIo);
static_assert(interp::kAnalogIoCount == config::kMaxAnalogIo);

interp::Units machine_units(const config::MachineConfig& config) {
  return config.linear_units == config::LinearUnits::inch ? interp::Units::inches
                                                          : interp::Units::mm;
}

double run_from_line_safe_z(const config::MachineConfig& config) {
  return config.cncd.run_from_line_safe_z.value_or(config.axes[2].max_limit);
}

interp::InterpOptions interpreter_options(const config::MachineConfig& config) {
  interp::InterpOptions options;
  options.machine_units = machine_units(config);
  options.parameter_file = config.parameter_file;
  options.tool_table = config.tool_table;
  options.subroutine_path = config.subroutine_path;
  options.probe_dir = config.cncd.probe_dir;
  options.state_files = {config.position_file};
  // As LinuxCNC's task looks for M100-M199: the first program directory, then [RS274NGC]
  // USER_M_PATH (the config lists them in that order).
  options.user_m_path = config.io.user_m_path;
  options.tool_change_quill_up = config.tool_change.quill_up;
  options.tool_change_with_spindle_on = config.tool_change.with_spindle_on;
  options.startup_code = config.startup_code;
  options.dialect = config.dialect == config::Dialect::numeryx ? interp::Dialect::numeryx
                                                               : interp::Dialect::linuxcnc;
  options.numeryx_clearance = config.numeryx_clearance;
  options.rigid_tapping = config.rigid_tapping;
  // #<_ini[SECTION]KEY>: the INI as loaded, kept alive by the options.
  if (std::shared_ptr<const config::IniFile> ini = config.ini) {
    options.ini_value = [ini](const std::string& section, const std::string& key) {
      return ini->value(section, key);
    };
  }
  return options;
}

}  // namespace cncd::pipeline
