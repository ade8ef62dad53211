// [SPINDLE_0], the [CNCD] signals, user M codes and the [EMCIO] tool change keys. What the
// values must be together (a driver's needs, directions, buses) is checked in validate_io.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

constexpr std::string_view kSpindle = "SPINDLE_0";

SignalAddress::Table register_table(const std::string& choice) {
  return choice == "hr" ? SignalAddress::Table::holding : SignalAddress::Table::input;
}

// LinuxCNC 2.9 (inispindle.cc): the reverse limits are magnitudes, a negative one counts as
// its absolute value; unset, they follow the forward ones.
void load_speeds(TypedReader& r, SpindleConfig& s) {
  if (const auto v = r.real(kSpindle, "MAX_FORWARD_VELOCITY")) s.max_forward_velocity = *v;
  if (const auto v = r.real(kSpindle, "MIN_FORWARD_VELOCITY")) s.min_forward_velocity = *v;
  s.max_reverse_velocity = s.max_forward_velocity;
  s.min_reverse_velocity = s.min_forward_velocity;
  if (const auto v = r.real(kSpindle, "MAX_REVERSE_VELOCITY")) {
    s.max_reverse_velocity = std::fabs(*v);
  }
  if (const auto v = r.real(kSpindle, "MIN_REVERSE_VELOCITY")) {
    s.min_reverse_velocity = std::fabs(*v);
  } else if (s.max_reverse_velocity == 0) {
    // MAX_REVERSE_VELOCITY = 0 forbids reverse; a forward minimum does not apply to it.
    s.min_reverse_velocity = 0;
  }
}

void load_spindle_gpio(TypedReader& r, SpindleConfig& s) {
  s.enable = r.signal(kSpindle, "ENABLE", true);
  s.direction = r.signal(kSpindle, "DIRECTION", true);
  s.pwm = r.signal(kSpindle, "PWM", true);
  if (const auto v = r.real(kSpindle, "PWM_FREQUENCY")) s.pwm_frequency = *v;
  if (const auto v = r.real(kSpindle, "PWM_MIN_DUTY")) s.pwm_min_duty = *v;
  s.encoder_a = r.signal(kSpindle, "ENCODER_A", true);
  s.encoder_b = r.signal(kSpindle, "ENCODER_B", true);
  s.encoder_index = r.signal(kSpindle, "ENCODER_INDEX", true);
  if (const auto v = r.integer(kSpindle, "ENCODER_PPR")) s.encoder_ppr = static_cast<int>(*v);
}

void load_spindle_modbus(TypedReader& r, SpindleConfig& s) {
  const auto integer = [&](const char* key, int& out) {
    if (const auto v = r.integer(kSpindle, key)) out = static_cast<int>(*v);
  };
  integer("MODBUS", s.modbus);
  integer("SLAVE", s.slave);
  if (const auto v = r.real(kSpindle, "SPEED_SCALE")) s.speed_scale = *v;
  integer("COMMAND_REGISTER", s.command_register);
  integer("SPEED_REGISTER", s.speed_register);
  integer("ACTUAL_SPEED_REGISTER", s.actual_speed_register);
  integer("STATUS_REGISTER", s.status_register);
  if (const auto v = r.choice(kSpindle, "ACTUAL_SPEED_TABLE")) {
    s.actual_speed_table = register_table(*v);
  }
  if (const auto v = r.choice(kSpindle, "STATUS_TABLE")) s.status_table = register_table(*v);
  integer("COMMAND_STOP", s.command_stop);
  integer("COMMAND_FORWARD", s.command_forward);
  integer("COMMAND_REVERSE", s.command_reverse);
  integer("RUNNING_BIT", s.running_bit);
  integer("AT_SPEED_BIT", s.at_speed_bit);
  integer("FAULT_BIT", s.fault_bit);
  integer("POSITION_REGISTER", s.position_register);
  if (const auto v = r.choice(kSpindle, "POSITION_TABLE")) s.position_table = register_table(*v);
  if (const auto v = r.choice(kSpindle, "POSITION_WIDTH")) s.position_width = *v == "16" ? 16 : 32;
  if (const auto v = r.choice(kSpindle, "WORD_ORDER")) s.position_high_first = *v != "LOW_FIRST";
  if (const auto v = r.real(kSpindle, "POSITION_SCALE")) s.position_scale = *v;
}

// Keys of one driver given with another: read by nobody, which the machinist should know.
void warn_ignored(TypedReader& r, const SpindleConfig& s, std::initializer_list<const char*> keys,
                  std::string_view driver) {
  const std::string used = s.driver == SpindleDriver::none   ? "none"
                           : s.driver == SpindleDriver::sim  ? "sim"
                           : s.driver == SpindleDriver::gpio ? "gpio"
                                                             : "modbus";
  for (const char* key : keys) {
    if (!r.given(kSpindle, key)) continue;
    r.entry(kSpindle, key);  // marked used: it has been reported
    r.warning(kSpindle, key, "ignored: a " + std::string(driver) + " key, and DRIVER is " + used);
  }
}

constexpr std::initializer_list<const char*> kGpioKeys = {
    "ENABLE",    "DIRECTION", "PWM",           "PWM_FREQUENCY", "PWM_MIN_DUTY",
    "ENCODER_A", "ENCODER_B", "ENCODER_INDEX", "ENCODER_PPR"};
constexpr std::initializer_list<const char*> kModbusKeys = {
    "MODBUS",          "SLAVE",
    "SPEED_SCALE",     "COMMAND_REGISTER",
    "SPEED_REGISTER",  "ACTUAL_SPEED_REGISTER",
    "STATUS_REGISTER", "ACTUAL_SPEED_TABLE",
    "STATUS_TABLE",    "COMMAND_STOP",
    "COMMAND_FORWARD", "COMMAND_REVERSE",
    "RUNNING_BIT",     "AT_SPEED_BIT",
    "FAULT_BIT",       "POSITION_REGISTER",
    "POSITION_TABLE",  "POSITION_WIDTH",
    "WORD_ORDER",      "POSITION_SCALE"};

// DIGITAL_OUTPUT_n and its kin: every key of the pattern in [CNCD], n below N.
template <std::size_t N>
void load_numbered(TypedReader& r, std::string_view prefix, std::array<SignalAddress, N>& out) {
  for (const auto& entry : r.ini().entries()) {
    if (entry.section != "CNCD" || entry.section_occurrence != 0) continue;
    const std::string_view key = entry.key;
    if (!key.starts_with(prefix) || key.size() == prefix.size() ||
        key.find_first_not_of("0123456789", prefix.size()) != std::string_view::npos) {
      continue;
    }
    const std::string_view digits = key.substr(prefix.size());
    const std::string range =
        std::string(prefix) + "0 .. " + std::string(prefix) + std::to_string(N - 1);
    if (digits.size() > 1 && digits.front() == '0') {
      r.problem("CNCD", key, "write the number without leading zeros; these are " + range);
      continue;
    }
    const std::size_t n = digits.size() > 3 ? N : std::stoul(std::string(digits));
    if (n >= N) {
      r.problem("CNCD", key, "number out of range: these are " + range);
      continue;
    }
    if (out[n].given() || r.failed("CNCD", key)) continue;  // a repeated key: check_keys
    out[n] = r.signal("CNCD", key);
  }
}

// LinuxCNC searches [DISPLAY] PROGRAM_PREFIX (else its nc_files directory) before
// USER_M_PATH; cncd's first program directory plays both parts.
void load_user_m_path(TypedReader& r, MachineConfig& c) {
  if (!c.program_dirs.empty()) c.io.user_m_path.push_back(c.program_dirs.front());
  for (const auto& dir : r.path_list("RS274NGC", "USER_M_PATH")) {
    std::error_code ec;
    std::filesystem::path absolute = std::filesystem::absolute(dir, ec).lexically_normal();
    if (!absolute.has_filename() && absolute.has_relative_path()) {
      absolute = absolute.parent_path();
    }
    if (!std::filesystem::is_directory(absolute, ec)) {
      r.warning("RS274NGC", "USER_M_PATH",
                "'" + printable(absolute.string()) +
                    "' is not a directory (yet): no user M code is found there until it is one");
    }
    if (std::find(c.io.user_m_path.begin(), c.io.user_m_path.end(), absolute) ==
        c.io.user_m_path.end()) {
      c.io.user_m_path.push_back(std::move(absolute));
    }
  }
}

// LinuxCNC reads 9, 6 or 3 numbers: X Y Z [A B C [U V W]].
void load_tool_change(TypedReader& r, ToolChangeConfig& t) {
  t.quill_up = r.boolean("EMCIO", "TOOL_CHANGE_QUILL_UP").value_or(false);
  t.with_spindle_on = r.boolean("EMCIO", "TOOL_CHANGE_WITH_SPINDLE_ON").value_or(false);
  const auto written = r.text("EMCIO", "TOOL_CHANGE_POSITION");
  if (!written) return;
  std::istringstream words{std::string(strip_trailing_comment(*written))};
  std::vector<double> numbers;
  std::string word;
  while (words >> word) {
    double value = 0;
    if (parse_number(word, value) != NumberError::none) {
      r.problem("EMCIO", "TOOL_CHANGE_POSITION", "'" + printable(word) + "' is not a number");
      return;
    }
    numbers.push_back(value);
  }
  if (numbers.empty()) return;
  if (numbers.size() != 3 && numbers.size() != 6 && numbers.size() != 9) {
    r.problem("EMCIO", "TOOL_CHANGE_POSITION",
              std::to_string(numbers.size()) +
                  " numbers; write 3 (X Y Z), 6 (X Y Z A B C) or 9 (X Y Z A B C U V W)");
    return;
  }
  t.has_position = true;
  for (std::size_t i = 0; i < numbers.size(); ++i) {
    t.position[i] = numbers[i];
    t.position_given[i] = true;
  }
}

}  // namespace

void load_spindle(TypedReader& r, MachineConfig& c) {
  SpindleConfig& s = c.spindle;
  for (const auto& header : r.ini().sections()) {
    if (header.occurrence == 0 && header.name.starts_with("SPINDLE_") && header.name != kSpindle &&
        header.name.size() > 8 &&
        header.name.find_first_not_of("0123456789", 8) == std::string::npos) {
      r.warning(header.name, "", "cncd drives one spindle, [SPINDLE_0]; section ignored");
    }
  }
  s.present = r.ini().has_section(kSpindle);
  s.source = r.where(kSpindle, "");
  if (const auto v = r.choice(kSpindle, "DRIVER")) {
    s.driver = *v == "none"     ? SpindleDriver::none
               : *v == "gpio"   ? SpindleDriver::gpio
               : *v == "modbus" ? SpindleDriver::modbus
                                : SpindleDriver::sim;
  }
  load_speeds(r, s);
  if (const auto v = r.real(kSpindle, "INCREMENT")) s.increment = *v;
  if (const auto v = r.real(kSpindle, "ACCELERATION")) s.acceleration = *v;
  if (const auto v = r.real(kSpindle, "AT_SPEED_TOLERANCE")) s.at_speed_tolerance = *v;
  if (const auto v = r.real(kSpindle, "AT_SPEED_TIMEOUT")) s.at_speed_timeout_s = *v;
  s.stop_on_pause = r.boolean(kSpindle, "STOP_ON_PAUSE").value_or(false);
  if (s.driver == SpindleDriver::gpio) {
    load_spindle_gpio(r, s);
  } else {
    warn_ignored(r, s, kGpioKeys, "gpio");
  }
  if (s.driver == SpindleDriver::modbus) {
    load_spindle_modbus(r, s);
  } else {
    warn_ignored(r, s, kModbusKeys, "modbus");
  }
}

void load_io(TypedReader& r, MachineConfig& c) {
  IoConfig& io = c.io;
  io.flood = r.signal("CNCD", "FLOOD_OUTPUT");
  io.mist = r.signal("CNCD", "MIST_OUTPUT");
  load_numbered(r, "DIGITAL_OUTPUT_", io.digital_outputs);
  load_numbered(r, "ANALOG_OUTPUT_", io.analog_outputs);
  load_numbered(r, "DIGITAL_INPUT_", io.digital_inputs);
  load_numbered(r, "ANALOG_INPUT_", io.analog_inputs);
  io.probe_input = r.signal("CNCD", "PROBE_INPUT");
  if (const auto v = r.real("CNCD", "USER_M_TIMEOUT")) io.user_m_timeout_s = *v;
  load_user_m_path(r, c);
  load_tool_change(r, c.tool_change);
}

}  // namespace cncd::config
