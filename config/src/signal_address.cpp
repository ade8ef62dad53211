// The one parser of signal addresses, and the table of what each kind of address can be.
#include <string>
#include <vector>

#include "cncd/config/evdev_codes.hpp"
#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

constexpr std::string_view kSyntax =
    "an address is gpio:LINE, gpio:!LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N, sim:NAME or "
    "evdev:DEVICE:CODE";

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  while (true) {
    const std::size_t at = text.find(separator);
    parts.push_back(text.substr(0, at));
    if (at == std::string_view::npos) return parts;
    text.remove_prefix(at + 1);
  }
}

// A name (of a line or a simulated signal): printable, without blanks or ':'.
std::string check_name(std::string_view name, std::string_view what) {
  if (name.empty()) return "empty " + std::string(what);
  for (const char ch : name) {
    const auto byte = static_cast<unsigned char>(ch);
    if (byte <= ' ' || byte == 0x7f) {
      return std::string(what) + " '" + printable(name) + "' contains a blank or control character";
    }
  }
  return "";
}

// A whole number in [0, max], written in decimal digits.
std::string parse_whole(std::string_view text, std::string_view what, int max, int& out) {
  if (text.empty()) return "missing " + std::string(what);
  const bool negative = text.front() == '-';
  const std::string_view digits = negative ? text.substr(1) : text;
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos) {
    return std::string(what) + " '" + printable(text) + "' is not a whole number";
  }
  long long value = 0;
  for (const char ch : digits) {
    value = value * 10 + (ch - '0');
    if (value > max) break;
  }
  if (negative || value > max) {
    return std::string(what) + " " + printable(text) + " is out of range 0.." + std::to_string(max);
  }
  out = static_cast<int>(value);
  return "";
}

std::string parse_table(std::string_view text, SignalAddress::Table& out) {
  const std::string table = to_lower(text);
  if (table == "coil") {
    out = SignalAddress::Table::coil;
  } else if (table == "hr") {
    out = SignalAddress::Table::holding;
  } else if (table == "di") {
    out = SignalAddress::Table::discrete;
  } else if (table == "ir") {
    out = SignalAddress::Table::input;
  } else if (table.empty()) {
    return "missing the table: coil, hr, di or ir";
  } else {
    return "unknown table '" + printable(text) + "': expected coil, hr, di or ir";
  }
  return "";
}

// parts[0] is "modbus".
std::string parse_modbus(const std::vector<std::string_view>& parts, SignalAddress& out) {
  const std::string usage = ": write modbus:BUS:SLAVE:coil|hr|di|ir:N";
  if (parts.size() > 5) return "too many parts" + usage;
  const auto missing = [&](const char* what) { return "missing the " + std::string(what) + usage; };
  if (auto e = parse_whole(parts[1], "bus", 99, out.bus); !e.empty()) return e;
  if (parts.size() < 3) return missing("slave");
  if (auto e = parse_whole(parts[2], "slave", 247, out.slave); !e.empty()) return e;
  if (parts.size() < 4) return missing("table (coil, hr, di or ir)");
  if (auto e = parse_table(parts[3], out.table); !e.empty()) return e;
  if (parts.size() < 5) return missing("coil or register number");
  const char* what = out.table == SignalAddress::Table::coil       ? "coil"
                     : out.table == SignalAddress::Table::discrete ? "discrete input"
                                                                   : "register";
  return parse_whole(parts[4], what, 65535, out.address);
}

// `rest` is what follows "evdev:": DEVICE up to the last ':', then CODE.
std::string parse_evdev(std::string_view rest, SignalAddress& out) {
  const std::string usage = ": write evdev:DEVICE:CODE, e.g. evdev:/dev/input/by-id/NAME:KEY_F1";
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string_view::npos) return "missing the event code" + usage;
  const std::string_view device = rest.substr(0, colon);
  const std::string_view code = rest.substr(colon + 1);
  if (device.empty()) return "missing the device" + usage;
  if (auto e = check_name(device, "device"); !e.empty()) return e;
  if (!device.starts_with('/')) {
    return "device '" + printable(device) + "' is not an absolute path" + usage;
  }
  if (code.empty()) return "missing the event code" + usage;
  const std::string upper = to_upper(code);
  if (!evdev_code(upper)) {
    return "unknown event code '" + printable(code) +
           "': write a KEY_*, BTN_*, REL_* or ABS_* name of <linux/input-event-codes.h>, as "
           "evtest prints it";
  }
  out.device = std::string(device);
  out.code = upper;
  return "";
}

}  // namespace

std::string parse_signal_address(std::string_view text, SignalAddress& out) {
  SignalAddress parsed;
  const std::string_view written = trim(text);
  parsed.text = std::string(written);
  if (written.empty()) return "empty address; " + std::string(kSyntax);
  const std::size_t colon = written.find(':');
  if (colon == std::string_view::npos) {
    return "'" + printable(written) + "' names no kind; " + std::string(kSyntax);
  }
  const std::string kind = to_lower(written.substr(0, colon));
  const std::string_view rest = written.substr(colon + 1);
  std::string error;
  if (kind == "gpio") {
    parsed.kind = SignalAddress::Kind::gpio;
    std::string_view line = rest;
    if (line.starts_with('!')) {
      parsed.active_low = true;
      line.remove_prefix(1);
    }
    error = check_name(line, "line");
    if (error.empty() && (line.find(':') != std::string_view::npos || line.starts_with('!'))) {
      error = "line '" + printable(line) + "' is not an offset or a line name";
    }
    parsed.line = std::string(line);
  } else if (kind == "modbus") {
    parsed.kind = SignalAddress::Kind::modbus;
    error = parse_modbus(split(written, ':'), parsed);
  } else if (kind == "sim") {
    parsed.kind = SignalAddress::Kind::sim;
    error = check_name(rest, "signal name");
    if (error.empty() && rest.find(':') != std::string_view::npos) {
      error = "signal name '" + printable(rest) + "' contains ':'";
    }
    parsed.name = std::string(rest);
  } else if (kind == "evdev") {
    parsed.kind = SignalAddress::Kind::evdev;
    error = parse_evdev(rest, parsed);
  } else {
    error = kind.empty() ? "missing the kind before ':'; " + std::string(kSyntax)
                         : "unknown kind '" + printable(written.substr(0, colon)) + "'; " +
                               std::string(kSyntax);
  }
  if (error.empty()) out = std::move(parsed);
  return error;
}

std::string line_active_low_key(std::string_view key) {
  if (key == "STEP_LINE" || key == "DIR_LINE" || !key.ends_with("_LINE")) return "";
  return std::string(key.substr(0, key.size() - 5)) + "_ACTIVE_LOW";
}

std::string parse_gpio_line_key(std::string_view key, std::string_view value,
                                std::optional<bool> active_low, GpioLineKey& out) {
  const std::string_view written = strip_trailing_comment(value);
  // A bare line is taken as written, as before addresses: a chip's line names may hold blanks.
  if (written.find(':') == std::string_view::npos) {
    out = GpioLineKey{std::string(written), active_low.value_or(false)};
    return "";
  }
  const std::string quoted = "'" + printable(written) + "': ";
  SignalAddress a;
  if (std::string e = parse_signal_address(written, a); !e.empty()) return quoted + e;
  const std::string low_key = line_active_low_key(key);
  if (a.kind != SignalAddress::Kind::gpio) {
    const bool output = key == "STEP_LINE" || key == "DIR_LINE" || key == "ENABLE_LINE";
    std::string why = quoted + (output ? "this output is driven" : "this input is read") +
                      " in the gpio driver's base thread, so it takes only a gpio line (LINE" +
                      (low_key.empty() ? " or gpio:LINE)" : ", gpio:LINE or gpio:!LINE)");
    if (key == "PROBE_LINE") why += "; [CNCD] PROBE_INPUT takes a gpio: or sim: probe";
    return why;
  }
  if (a.active_low && low_key.empty()) {
    const std::string name(key.substr(0, key.size() - 5));
    return quoted + std::string(key) + " takes no '!': there is no " + name + "_ACTIVE_LOW" +
           (key == "DIR_LINE" ? " (a negative SCALE reverses the direction)" : "");
  }
  if (a.active_low && active_low) {
    if (*active_low) {
      return quoted + "active low is given twice, by '!' and by " + low_key + " = 1: give it once";
    }
    return quoted + "'!' makes the line active low, but " + low_key +
           " = 0 says it is not: give the polarity once, by '!' or by " + low_key;
  }
  out = GpioLineKey{a.line, a.active_low || active_low.value_or(false)};
  return "";
}

namespace {

// The kind of event an evdev address's code gives (parse_signal_address checked the name).
EvdevCode::Type evdev_type(const SignalAddress& a) {
  const auto code = evdev_code(a.code);
  return code ? code->type : EvdevCode::Type::key;
}

// Only the panel reads input devices, and each use wants one type of event.
std::string evdev_refusal(const SignalAddress& a, SignalUse use) {
  using Type = EvdevCode::Type;
  const Type type = evdev_type(a);
  switch (use) {
    case SignalUse::panel_button:
      if (type == Type::key) return "";
      return a.code + " is not a button: a button or switch is a KEY_* or BTN_* code";
    case SignalUse::panel_counter:
      if (type == Type::rel) return "";
      return a.code + " does not count: a counter is a REL_* code (a jog dial or wheel)";
    case SignalUse::panel_analog:
      if (type == Type::abs) return "";
      return a.code + " is not analog: an analog knob is an ABS_* code";
    case SignalUse::panel_encoder:
      return "an input device gives no quadrature channel: wire its REL_* code to the _COUNTS "
             "key instead";
    case SignalUse::digital_output:
    case SignalUse::analog_output:
      return "an input device (evdev) cannot be written: use gpio, a modbus coil or sim";
    case SignalUse::digital_input:
    case SignalUse::analog_input:
      break;
  }
  return "an input device (evdev) is read only by [PANEL] keys";
}

}  // namespace

std::string signal_use_refusal(const SignalAddress& a, SignalUse use) {
  using Kind = SignalAddress::Kind;
  using Table = SignalAddress::Table;
  if (a.kind == Kind::evdev) return evdev_refusal(a, use);
  const bool sim = a.kind == Kind::sim;
  const bool gpio = a.kind == Kind::gpio;
  const bool modbus = a.kind == Kind::modbus;
  const Table t = a.table;
  const bool register_table = modbus && (t == Table::input || t == Table::holding);
  switch (use) {
    case SignalUse::digital_output:
      if (sim || gpio || (modbus && t == Table::coil)) return "";
      if (t == Table::holding) return "a holding register is not a bit: use a coil";
      return "a discrete input or input register cannot be written: use a coil";
    case SignalUse::analog_output:
      if (sim || (modbus && t == Table::holding)) return "";
      if (gpio) return "a gpio line is not analog: use a holding register (hr)";
      return "an analog output is a holding register (hr)";
    case SignalUse::digital_input:
    case SignalUse::panel_button:
      if (sim || gpio || (modbus && (t == Table::discrete || t == Table::coil))) return "";
      return "a register is not a bit: use a discrete input (di) or a coil";
    case SignalUse::analog_input:
    case SignalUse::panel_analog:
      if (sim || register_table) return "";
      if (gpio) return "a gpio line is not analog: use an input (ir) or holding register (hr)";
      return "a bit is not analog: use an input (ir) or holding register (hr)";
    case SignalUse::panel_counter:
      if (sim || register_table) return "";
      if (gpio) return "a gpio line gives no count: wire an encoder to the _A and _B keys";
      return "a bit gives no count: use an input (ir) or holding register (hr)";
    case SignalUse::panel_encoder:
      if (sim || gpio) return "";
      return "a Modbus signal is read an update period apart, far too seldom for quadrature: "
             "wire the encoder to gpio lines, or its count to the _COUNTS key";
  }
  return "";
}

}  // namespace cncd::config
