// A signal's address in an INI key (docs/drivers.md, "Signal addresses"): the one syntax for
// every input and output of the machine.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cncd::config {

// Where a value came from, for messages in the form FILE:LINE.
struct SourceRef {
  std::string file;
  int line = 0;
};

// A signal named in an INI key by its address (docs/drivers.md, "Signal addresses"):
//   gpio:LINE                    a line of [GPIO] CHIP, by offset or name; "gpio:!LINE" is
//                                active low
//   modbus:BUS:SLAVE:coil:N      a coil of slave SLAVE on the [MODBUS_BUS] bus
//   modbus:BUS:SLAVE:hr:N        a holding register
//   modbus:BUS:SLAVE:di:N        a discrete input
//   modbus:BUS:SLAVE:ir:N        an input register
//   sim:NAME                     a simulated signal (tests and demos set and read it)
//   evdev:DEVICE:CODE            a Linux input event device (a USB pendant): KEY_* and BTN_*
//                                codes are buttons, REL_* codes count (a jog dial), ABS_*
//                                codes are analog; DEVICE is a path (it may hold ':'; the last
//                                ':' ends it)
// The kind and the table may be written in any case. BUS is 0..99, SLAVE 0..247, N 0..65535;
// LINE and NAME have no blanks and no ':'. An empty INI value means "not connected".
struct SignalAddress {
  enum class Kind : std::uint8_t { none, gpio, modbus, sim, evdev };
  enum class Table : std::uint8_t { coil, holding, discrete, input };
  Kind kind = Kind::none;
  std::string line;         // gpio: offset or name of the line
  bool active_low = false;  // gpio: written with a '!' before the line
  int bus = 0;              // modbus: n of [MODBUS_n]
  int slave = 0;            // modbus: slave id
  Table table = Table::coil;
  int address = 0;     // modbus: coil or register number (0-based, the protocol's address)
  std::string name;    // sim: the signal's name
  std::string device;  // evdev: the event device's path
  std::string code;    // evdev: the event code's name, upper case ("KEY_F1", "REL_DIAL")
  std::string text;    // the address as written, for messages
  SourceRef source;    // the key that named it
  bool given() const { return kind != Kind::none; }
};

// Parses a signal address (the syntax above) into `out`, keeping `text` as written (trimmed);
// `source` is left to the caller. Returns "" when it parsed, else what is wrong (then `out` is
// unchanged). Any thread may call it.
std::string parse_signal_address(std::string_view text, SignalAddress& out);

// What a line key of [GPIO] or of a step/dir joint names (ESTOP_LINE, PROBE_LINE, STEP_LINE,
// DIR_LINE, ENABLE_LINE, HOME_SWITCH_LINE, MIN_LIMIT_LINE, MAX_LIMIT_LINE). These keys predate
// signal addresses: their value is a bare line ("GPIO4", "17") or a gpio: address, and
// "gpio:!LINE" stands for the key's *_ACTIVE_LOW = 1.
struct GpioLineKey {
  std::string line;         // offset or name; empty: not connected
  bool active_low = false;  // the '!' or the *_ACTIVE_LOW key
};

// The key that makes the line of `key` active low ("ESTOP_LINE": "ESTOP_ACTIVE_LOW"), or ""
// for STEP_LINE and DIR_LINE, which have none.
std::string line_active_low_key(std::string_view key);

// Reads `value`, the value of the line key `key`; `active_low` is the value of its *_ACTIVE_LOW
// key when that is given. Returns "" and fills `out`, else what is wrong (then `out` is
// unchanged): a '!' the key cannot take or that its *_ACTIVE_LOW key gives again, or an
// address of another kind (the gpio driver reads and drives these lines in its base thread).
// Every reader of these keys goes through it, so that they all see the same line.
std::string parse_gpio_line_key(std::string_view key, std::string_view value,
                                std::optional<bool> active_low, GpioLineKey& out);

}  // namespace cncd::config
