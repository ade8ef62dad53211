#include <map>
#include <vector>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

constexpr std::string_view kTypedSections[] = {
    "EMC", "EMCMOT", "TASK", "RS274NGC", "EMCIO", "TRAJ", "KINS", "DISPLAY", "CNCD", "SPINDLE_0"};

std::string at_line(const SourceRef& ref) {
  return ref.file + ":" + std::to_string(ref.line);
}

void check_limits(TypedReader& r, const std::string& section, double min, double max) {
  if (min < max || r.failed(section, "MIN_LIMIT") || r.failed(section, "MAX_LIMIT")) return;
  if (min == max) {
    r.warning(section, "MAX_LIMIT",
              "MIN_LIMIT equals MAX_LIMIT (" + format_number(min) + "); it cannot move");
    return;
  }
  r.problem(section, r.given(section, "MAX_LIMIT") ? "MAX_LIMIT" : "MIN_LIMIT",
            "MIN_LIMIT " + format_number(min) + " must be below MAX_LIMIT " + format_number(max));
}

void check_spindle_override(TypedReader& r, const MachineConfig& c) {
  if (c.min_spindle_override <= c.max_spindle_override ||
      r.failed("DISPLAY", "MIN_SPINDLE_OVERRIDE") || r.failed("DISPLAY", "MAX_SPINDLE_OVERRIDE"))
    return;
  const bool min_given = r.given("DISPLAY", "MIN_SPINDLE_OVERRIDE");
  r.problem("DISPLAY", min_given ? "MIN_SPINDLE_OVERRIDE" : "MAX_SPINDLE_OVERRIDE",
            "MIN_SPINDLE_OVERRIDE " + format_number(c.min_spindle_override) +
                (min_given ? "" : " (the default)") + " must not be above MAX_SPINDLE_OVERRIDE " +
                format_number(c.max_spindle_override));
}

// Homing ends with the joint at HOME; beyond a soft limit it would be stuck there (LinuxCNC
// stops with "Exceeded soft limit" right after homing). HOME_OFFSET, the switch position, may
// lie beyond a limit: shipped configs put the switch just past the end of travel.
void check_home(TypedReader& r, const MachineConfig& c, const std::string& s,
                const JointConfig& j) {
  if (r.failed(s, "HOME") || r.failed(s, "MIN_LIMIT") || r.failed(s, "MAX_LIMIT") ||
      j.min_limit > j.max_limit)
    return;
  const bool below = j.home < j.min_limit;
  if (!below && j.home <= j.max_limit) return;
  const char* key = below ? "MIN_LIMIT" : "MAX_LIMIT";
  // Joint limits not given follow the axis (load_joint).
  const std::string limit_from = r.given(s, key) || j.axis == '\0' || !c.axis(j.axis).present
                                     ? std::string(key)
                                     : "[AXIS_" + std::string(1, j.axis) + "] " + key;
  r.problem(s, "HOME",
            format_number(j.home) + (r.given(s, "HOME") ? "" : " (the default)") + " is " +
                (below ? "below " : "above ") + limit_from + " " +
                format_number(below ? j.min_limit : j.max_limit) +
                ": homing would leave the joint beyond its soft limit");
}

void check_joint(TypedReader& r, const MachineConfig& c, int index, const JointConfig& j) {
  const std::string s = "JOINT_" + std::to_string(index);
  check_limits(r, s, j.min_limit, j.max_limit);
  if (j.axis != '\0') {
    const std::string as = std::string("AXIS_") + j.axis;
    const AxisConfig& axis = c.axis(j.axis);
    if (axis.present || r.ini().has_section(as)) {
      if (j.min_limit > axis.min_limit && !r.failed(as, "MIN_LIMIT") && !r.failed(s, "MIN_LIMIT")) {
        r.problem(s, "MIN_LIMIT",
                  format_number(j.min_limit) + " is narrower than [" + as + "] MIN_LIMIT " +
                      format_number(axis.min_limit) +
                      "; joint limits must include the axis limits");
      }
      if (j.max_limit < axis.max_limit && !r.failed(as, "MAX_LIMIT") && !r.failed(s, "MAX_LIMIT")) {
        r.problem(s, "MAX_LIMIT",
                  format_number(j.max_limit) + " is narrower than [" + as + "] MAX_LIMIT " +
                      format_number(axis.max_limit) +
                      "; joint limits must include the axis limits");
      }
    }
  }
  check_home(r, c, s, j);
  if (j.min_ferror > j.ferror) {
    r.warning(s, "MIN_FERROR", "larger than FERROR " + format_number(j.ferror));
  }
}

// LinuxCNC reads only the first section of a name; a later one that says something else is
// a trap for whoever edits it.
void check_repeated_section(TypedReader& r, const IniSection& header, const IniSection& first) {
  bool differs = false;
  for (const auto& entry : r.ini().entries()) {
    if (entry.section != header.name || entry.section_occurrence != header.occurrence) continue;
    const IniEntry* original = r.ini().find(header.name, entry.key);
    if (original == nullptr || original->value != entry.value) {
      r.problems().push_back(Problem{entry.source.file, entry.source.line, header.name, entry.key,
                                     "ignored: [" + header.name +
                                         "] appears again here, and only "
                                         "the first one (" +
                                         at_line(first.source) + ") is read"});
      differs = true;
    }
  }
  if (!differs) r.warning(header.name, "", "section repeated at " + at_line(header.source));
}

// Step/dir and Modbus keys: ranges come from the key table; here, what a joint's DRIVER needs.
// A machine whose driver could not start is an invalid configuration, found at load time.

void check_gpio_joint(TypedReader& r, const MachineConfig& c, const std::string& s,
                      const JointConfig& j) {
  for (const char* key : {"STEPLEN", "STEPSPACE", "DIRSETUP", "DIRHOLD"})
    r.integer(s, key);
  for (const char* key : {"STEPGEN_MAXVEL", "STEPGEN_MAXACCEL"})
    r.real(s, key);
  for (const char* key : {"ENABLE_ACTIVE_LOW", "HOME_SWITCH_ACTIVE_LOW", "MIN_LIMIT_ACTIVE_LOW",
                          "MAX_LIMIT_ACTIVE_LOW"})
    r.boolean(s, key);
  for (const char* key : {"ENABLE_LINE", "HOME_SWITCH_LINE", "MIN_LIMIT_LINE", "MAX_LIMIT_LINE"})
    r.gpio_line(s, key);
  for (const char* key : {"STEP_LINE", "DIR_LINE"}) {
    const auto v = r.gpio_line(s, key);
    if (!r.failed(s, key) && (!v || v->line.empty())) {
      r.problem(s, key, "missing: DRIVER = gpio needs a line offset or name");
    }
  }
  if (j.scale == 0 && !r.failed(s, "SCALE")) {
    r.problem(s, r.given(s, "SCALE") ? "SCALE" : "DRIVER",
              "DRIVER = gpio needs SCALE (steps per unit), not 0");
  }
  if (c.base_period_ns <= 0 && !r.failed("EMCMOT", "BASE_PERIOD")) {
    r.problem(s, "DRIVER", "DRIVER = gpio needs a base thread: set [EMCMOT] BASE_PERIOD");
  }
  const auto chip = r.ini().value("GPIO", "CHIP");
  if (!chip || chip->empty()) {
    r.problem(s, "DRIVER", "DRIVER = gpio needs [GPIO] CHIP (gpiochip0, or vcd:FILE)");
  }
}

void check_modbus_joint(TypedReader& r, const std::string& s, const JointConfig& j) {
  for (const char* key :
       {"TARGET_REGISTER", "CONTROL_REGISTER", "POSITION_REGISTER", "STATUS_REGISTER"})
    r.integer(s, key);
  r.choice(s, "REGISTER_WIDTH");
  r.choice(s, "WORD_ORDER");
  if (!r.given(s, "SLAVE")) {
    r.problem(s, "DRIVER", "DRIVER = modbus needs SLAVE (unit id)");
  }
  r.integer(s, "SLAVE");
  if (j.scale == 0 && !r.failed(s, "SCALE")) {
    r.problem(s, r.given(s, "SCALE") ? "SCALE" : "DRIVER",
              "DRIVER = modbus needs SCALE (counts per unit), not 0");
  }
  if (!r.given(s, "MODBUS")) {
    r.problem(s, "DRIVER", "DRIVER = modbus needs MODBUS = n naming a [MODBUS_n] section");
    return;
  }
  const auto bus = r.integer(s, "MODBUS");
  if (bus && !r.ini().has_section("MODBUS_" + std::to_string(*bus))) {
    r.problem(s, "MODBUS", "no section [MODBUS_" + std::to_string(*bus) + "] in the file");
  }
}

void check_modbus_bus(TypedReader& r, const std::string& s) {
  const auto transport = r.choice(s, "TRANSPORT");
  for (const char* key :
       {"PORT", "BAUD", "DATA_BITS", "STOP_BITS", "TIMEOUT_MS", "UPDATE_PERIOD_MS", "RETRIES"})
    r.integer(s, key);
  r.choice(s, "PARITY");
  const auto host = r.text(s, "HOST");
  const auto device = r.text(s, "DEVICE");
  if (transport == "tcp" && (!host || host->empty())) {
    r.problem(s, "HOST", "missing: TRANSPORT = tcp needs the drive's address");
  }
  if (transport == "rtu" && (!device || device->empty())) {
    r.problem(s, "DEVICE", "missing: TRANSPORT = rtu needs a serial device");
  }
}

void check_drivers(TypedReader& r, const MachineConfig& c) {
  if (r.ini().has_section("GPIO")) {
    r.text("GPIO", "CHIP");
    r.boolean("GPIO", "ESTOP_ACTIVE_LOW");
    r.boolean("GPIO", "PROBE_ACTIVE_LOW");
    r.gpio_line("GPIO", "ESTOP_LINE");
    r.gpio_line("GPIO", "PROBE_LINE");
    r.integer("GPIO", "DEBOUNCE_NS");
  }
  for (const auto& header : r.ini().sections()) {
    if (header.occurrence == 0 && find_key_spec(header.name, "TRANSPORT") != nullptr) {
      check_modbus_bus(r, header.name);
    }
  }
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    const std::string s = "JOINT_" + std::to_string(i);
    if (c.joints[i].driver == "gpio") check_gpio_joint(r, c, s, c.joints[i]);
    if (c.joints[i].driver == "modbus") check_modbus_joint(r, s, c.joints[i]);
  }
}

}  // namespace

void validate(TypedReader& r, const MachineConfig& c) {
  // LinuxCNC accepts a base thread as slow as the servo thread (shipped configs do it).
  if (c.base_period_ns > c.servo_period_ns) {
    r.problem("EMCMOT", "BASE_PERIOD",
              std::to_string(c.base_period_ns) + " ns must not be longer than SERVO_PERIOD " +
                  std::to_string(c.servo_period_ns) + " ns");
  }
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const std::string s = std::string("AXIS_") + kAxisLetters[i];
    if (c.axes[i].present || r.ini().has_section(s)) {
      check_limits(r, s, c.axes[i].min_limit, c.axes[i].max_limit);
    }
  }
  for (std::size_t i = 0; i < c.joints.size(); ++i) {
    check_joint(r, c, static_cast<int>(i), c.joints[i]);
  }
  check_drivers(r, c);
  check_spindle_override(r, c);
  if (c.joint_count == 0) return;
  for (const auto& header : r.ini().sections()) {
    const std::string_view name = header.name;
    if (!name.starts_with("JOINT_") || header.occurrence > 0) continue;
    double index = 0;
    if (parse_number(name.substr(6), index) != NumberError::none) continue;
    // LinuxCNC ignores such a section, and shipped configs keep spare ones.
    if (index >= c.joint_count && index < kMaxJoints) {
      r.warning(header.name, "",
                "joint index out of range: [KINS] JOINTS = " + std::to_string(c.joint_count) +
                    ", so joints are 0 .. " + std::to_string(c.joint_count - 1) +
                    "; section ignored");
    }
  }
}

bool check_sections(TypedReader& r) {
  std::vector<const IniSection*> numbered_axes;
  bool any_joint = false;
  std::map<std::string, const IniSection*, std::less<>> first;
  for (const auto& header : r.ini().sections()) {
    const std::string& name = header.name;
    const auto add = [&](std::string message) {
      r.problems().push_back(
          Problem{header.source.file, header.source.line, name, "", std::move(message)});
    };
    if (header.occurrence == 0) first[name] = &header;
    if (name.starts_with("JOINT_")) {
      any_joint = true;
      const std::string_view number = std::string_view(name).substr(6);
      const bool digits = !number.empty() && number.size() <= 3 &&
                          number.find_first_not_of("0123456789") == std::string_view::npos &&
                          (number == "0" || number.front() != '0');
      if (!digits) {
        add("not a joint section; joints are [JOINT_0] .. [JOINT_" +
            std::to_string(kMaxJoints - 1) + "]");
      } else if (std::stoi(std::string(number)) >= kMaxJoints) {
        add("joint index out of range; joints are numbered 0 .. " + std::to_string(kMaxJoints - 1));
      } else if (header.occurrence > 0) {
        add("duplicate section; the first is at " + at_line(first[name]->source));
      }
    } else if (name.starts_with("AXIS_")) {
      const std::string_view letter = std::string_view(name).substr(5);
      if (!letter.empty() && letter.find_first_not_of("0123456789") == std::string_view::npos) {
        numbered_axes.push_back(&header);
      } else if (letter.size() == 1 && kAxisLetters.find(letter.front()) != std::string::npos) {
        if (header.occurrence > 0) {
          add("duplicate section; the first is at " + at_line(first[name]->source));
        }
      } else if (letter.size() == 1 && axis_index(letter.front()) >= 0) {
        add("section names are case-sensitive: LinuxCNC ignores [" + name + "], write [AXIS_" +
            to_upper(letter) + "]");
      } else {
        add("not an axis section; axes are [AXIS_X] .. [AXIS_W] with a letter of " +
            std::string(kAxisLetters));
      }
    } else if (header.occurrence > 0) {
      for (const auto typed : kTypedSections) {
        if (name == typed) check_repeated_section(r, header, *first[name]);
      }
    }
  }
  if (numbered_axes.empty()) return true;
  const IniSection& at = *numbered_axes.front();
  if (!any_joint) {
    r.problems().push_back(Problem{
        at.source.file, at.source.line, at.name, "",
        "LinuxCNC 2.7-style configuration (numbered [AXIS_n] sections, no [JOINT_n]); convert "
        "it with LinuxCNC's update_ini to [JOINT_n] and [AXIS_<letter>] sections"});
    return false;
  }
  for (const IniSection* header : numbered_axes) {
    r.problems().push_back(Problem{header->source.file, header->source.line, header->name, "",
                                   "numbered axis sections are LinuxCNC 2.7 style; axes are "
                                   "[AXIS_X] .. [AXIS_W], joints [JOINT_n]"});
  }
  return true;
}

}  // namespace cncd::config
