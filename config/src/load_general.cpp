#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <numbers>
#include <utility>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

bool near(double value, double target) {
  return std::fabs(value - target) <= 1e-6 * target;
}

// LINEAR_UNITS and ANGULAR_UNITS may also be written as LinuxCNC's factor (machine units per
// mm or per degree). True when the key holds a number: then `units` is the one of `factors` it
// is near, or a problem says it is none of `names`.
template <typename Units>
bool load_units_factor(TypedReader& r, const char* key,
                       std::initializer_list<std::pair<double, Units>> factors,
                       const std::string& names, Units& units) {
  double factor = 0;
  const IniEntry* e = r.entry("TRAJ", key);
  if (e == nullptr || parse_number(strip_trailing_comment(e->value), factor) != NumberError::none)
    return false;
  for (const auto& [value, named] : factors) {
    if (near(factor, value)) {
      units = named;
      return true;
    }
  }
  r.problem("TRAJ", key, "factor " + e->value + " is " + names);
  return true;
}

void load_linear_units(TypedReader& r, MachineConfig& c) {
  if (load_units_factor(
          r, "LINEAR_UNITS", {{1.0, LinearUnits::mm}, {1.0 / 25.4, LinearUnits::inch}},
          "neither mm (1) nor inch (" + format_number(1.0 / 25.4) + ")", c.linear_units)) {
    return;
  }
  const auto units = r.choice("TRAJ", "LINEAR_UNITS");
  if (!units) return;
  c.linear_units = (*units == "mm" || *units == "metric") ? LinearUnits::mm : LinearUnits::inch;
}

// LinuxCNC's PLANNER_TYPE = 1 asks for S-curve profiles and needs MAX_LINEAR_JERK >= 1, else
// it plans trapezoids and says so; unset, a MAX_LINEAR_JERK alone asks for them.
void load_planner_type(TypedReader& r, MachineConfig& c) {
  const auto type = r.integer("TRAJ", "PLANNER_TYPE");
  if (!type) {
    c.scurve = c.max_linear_jerk > 0;
  } else if (*type == 0) {
    if (c.max_linear_jerk > 0)
      r.warning("TRAJ", "PLANNER_TYPE",
                "PLANNER_TYPE = 0 plans trapezoidal profiles: MAX_LINEAR_JERK is not applied");
  } else if (c.max_linear_jerk >= 1.0) {
    c.scurve = true;
  } else {
    r.warning("TRAJ", "PLANNER_TYPE",
              "PLANNER_TYPE = 1 (S-curve) needs MAX_LINEAR_JERK >= 1 (got " +
                  format_number(c.max_linear_jerk) + "): planning trapezoidal profiles");
  }
}

void load_angular_units(TypedReader& r, MachineConfig& c) {
  if (load_units_factor(r, "ANGULAR_UNITS",
                        {{1.0, AngularUnits::degree},
                         {std::numbers::pi / 180.0, AngularUnits::radian},
                         {0.9, AngularUnits::grad}},
                        "none of degree (1), radian, grad (0.9)", c.angular_units)) {
    return;
  }
  const auto units = r.choice("TRAJ", "ANGULAR_UNITS");
  if (!units) return;
  if (*units == "degree" || *units == "deg") {
    c.angular_units = AngularUnits::degree;
  } else if (*units == "radian" || *units == "rad") {
    c.angular_units = AngularUnits::radian;
  } else {
    c.angular_units = AngularUnits::grad;
  }
}

void load_coordinates(TypedReader& r, MachineConfig& c) {
  if (!r.given("TRAJ", "COORDINATES")) {
    r.warning("TRAJ", "COORDINATES", "not given; XYZ assumed");
  }
  const std::string written = r.text("TRAJ", "COORDINATES").value_or("XYZ");
  std::string letters;
  for (const char ch : strip_trailing_comment(written)) {
    if (ch == ' ' || ch == '\t') continue;
    if (axis_index(ch) < 0) {
      r.problem("TRAJ", "COORDINATES",
                "'" + printable(written) + "': '" + printable(std::string(1, ch)) +
                    "' is not an axis letter (" + std::string(kAxisLetters) + ")");
      return;
    }
    letters += static_cast<char>(kAxisLetters[static_cast<std::size_t>(axis_index(ch))]);
  }
  if (letters.empty()) {
    r.problem("TRAJ", "COORDINATES", "no axis letters given");
    return;
  }
  if (letters.size() > static_cast<std::size_t>(kMaxJoints)) {
    r.problem("TRAJ", "COORDINATES", "more than " + std::to_string(kMaxJoints) + " letters");
    return;
  }
  c.coordinates = letters;
}

// `EMCMOT = motmod num_extrajoints=1`: extra joints are the last ones, driven by no axis.
void load_extra_joints(TypedReader& r, MachineConfig& c) {
  const std::string motmod = r.text("EMCMOT", "EMCMOT").value_or("");
  const std::string_view marker = "num_extrajoints=";
  const std::size_t at = motmod.find(marker);
  if (at == std::string::npos) return;
  const std::string_view rest = std::string_view(motmod).substr(at + marker.size());
  double count = 0;
  if (parse_number(rest.substr(0, rest.find_first_of(" \t")), count) != NumberError::none ||
      count < 0 || count > kMaxJoints || std::trunc(count) != count) {
    r.problem("EMCMOT", "EMCMOT",
              "num_extrajoints must be a whole number 0.." + std::to_string(kMaxJoints));
    return;
  }
  c.extra_joints = static_cast<int>(count);
}

void load_cncd(TypedReader& r, CncdConfig& cncd) {
  if (const auto v = r.path("CNCD", "SOCKET")) cncd.socket_path = v->string();
  cncd.read_group = std::string(strip_trailing_comment(r.text("CNCD", "READ_GROUP").value_or("")));
  cncd.control_group =
      std::string(strip_trailing_comment(r.text("CNCD", "CONTROL_GROUP").value_or("")));
  if (const auto v = r.integer("CNCD", "MAX_CONNECTIONS"))
    cncd.max_connections = static_cast<int>(*v);
  if (const auto v = r.integer("CNCD", "MAX_CONNECTIONS_PER_USER"))
    cncd.max_connections_per_user = static_cast<int>(*v);
  if (const auto v = r.integer("CNCD", "CONTROL_RESERVE"))
    cncd.control_reserve = static_cast<int>(*v);
  if (cncd.control_reserve >= cncd.max_connections) {
    r.problem("CNCD", "CONTROL_RESERVE",
              "must be less than MAX_CONNECTIONS (" + std::to_string(cncd.max_connections) +
                  "): readers would get no connection at all");
  }
  if (const auto v = r.integer("CNCD", "RT_PRIORITY")) cncd.rt_priority = static_cast<int>(*v);
  if (const auto v = r.integer("CNCD", "RT_CPU")) cncd.rt_cpu = static_cast<int>(*v);
  cncd.run_from_line_safe_z = r.real("CNCD", "RUN_FROM_LINE_SAFE_Z");
  if (const auto v = r.choice("CNCD", "LOG_LEVEL")) {
    cncd.log_level = *v == "warning" ? "warn" : *v;
  }
  refuse_unknown_keys(r, "CNCD", "cncd's own section");
}

// `dir` absolute, without "." or ".." and without a trailing slash.
std::filesystem::path absolute_dir(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::path out = std::filesystem::absolute(dir, ec).lexically_normal();
  if (!out.has_filename() && out.has_relative_path()) out = out.parent_path();
  return out;
}

// A program directory as the INI writes it: relative to the INI's directory, "~" for $HOME as
// in LinuxCNC's PROGRAM_PREFIX = ~/linuxcnc/nc_files.
std::optional<std::filesystem::path> program_dir(TypedReader& r, std::string_view section,
                                                 std::string_view key, std::string_view item,
                                                 const LoadOptions& options) {
  std::filesystem::path dir;
  if (item == "~" || item.starts_with("~/")) {
    const char* home = options.getenv("HOME");
    if (home == nullptr || *home == '\0') {
      r.warning(section, key, "'" + printable(item) + "': $HOME is not set; left out");
      return std::nullopt;
    }
    dir = std::filesystem::path(home) / item.substr(std::min<std::size_t>(2, item.size()));
  } else {
    dir = item;
    if (dir.is_relative()) dir = r.ini().directory() / dir;
  }
  dir = absolute_dir(dir);
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    r.warning(section, key,
              "'" + printable(dir.string()) +
                  "' is not a directory (yet): no program opens from there until it is one");
  }
  return dir;
}

}  // namespace

void load_program_dirs(TypedReader& r, MachineConfig& c, const LoadOptions& options) {
  const auto add = [&](std::string_view section, std::string_view key, std::string_view item) {
    item = trim(item);
    if (item.empty()) return;
    if (auto dir = program_dir(r, section, key, item, options)) {
      c.program_dirs.push_back(std::move(*dir));
    }
  };
  const std::string prefix = r.text("DISPLAY", "PROGRAM_PREFIX").value_or("");
  const std::string dirs = r.text("CNCD", "PROGRAM_DIRS").value_or("");
  add("DISPLAY", "PROGRAM_PREFIX", prefix);
  std::string_view rest = dirs;
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    add("CNCD", "PROGRAM_DIRS", rest.substr(0, colon));
    if (colon == std::string_view::npos) break;
    rest.remove_prefix(colon + 1);
  }
  // Neither given: programs kept beside the machine's INI, and nothing else on the system.
  if (trim(prefix).empty() && trim(dirs).empty()) {
    c.program_dirs.push_back(absolute_dir(r.ini().directory()));
  }
}

void load_general(TypedReader& r, MachineConfig& c) {
  c.machine_name = r.text("EMC", "MACHINE").value_or("");
  if (const auto v = r.integer("EMCMOT", "SERVO_PERIOD")) c.servo_period_ns = *v;
  if (const auto v = r.integer("EMCMOT", "BASE_PERIOD")) c.base_period_ns = *v;
  load_extra_joints(r, c);
  if (const auto v = r.real("TASK", "CYCLE_TIME")) c.task_cycle_time_s = *v;

  c.startup_code = r.text("RS274NGC", "RS274NGC_STARTUP_CODE").value_or("");
  c.subroutine_path = r.path_list("RS274NGC", "SUBROUTINE_PATH");
  if (const auto v = r.choice("RS274NGC", "DIALECT")) {
    c.dialect = *v == "numeryx" ? Dialect::numeryx : Dialect::linuxcnc;
  }
  c.numeryx_clearance = r.real("RS274NGC", "NUMERYX_CLEARANCE");
  c.rigid_tapping = r.boolean("RS274NGC", "RIGID_TAPPING").value_or(false);

  load_coordinates(r, c);
  load_linear_units(r, c);
  load_angular_units(r, c);
  // Zero marks "not given": load_motion derives these from the axes.
  c.default_linear_velocity = r.real("TRAJ", "DEFAULT_LINEAR_VELOCITY").value_or(0);
  c.max_linear_velocity = r.real("TRAJ", "MAX_LINEAR_VELOCITY").value_or(0);
  c.default_linear_acceleration = r.real("TRAJ", "DEFAULT_LINEAR_ACCELERATION").value_or(0);
  c.max_linear_acceleration = r.real("TRAJ", "MAX_LINEAR_ACCELERATION").value_or(0);
  c.max_linear_jerk = r.real("TRAJ", "MAX_LINEAR_JERK").value_or(0);
  load_planner_type(r, c);
  c.no_force_homing = r.boolean("TRAJ", "NO_FORCE_HOMING").value_or(false);

  if (const auto v = r.real("DISPLAY", "MAX_FEED_OVERRIDE")) c.max_feed_override = *v;
  if (const auto v = r.real("DISPLAY", "MIN_SPINDLE_OVERRIDE")) c.min_spindle_override = *v;
  if (const auto v = r.real("DISPLAY", "MAX_SPINDLE_OVERRIDE")) c.max_spindle_override = *v;
  load_cncd(r, c.cncd);
}

}  // namespace cncd::config
