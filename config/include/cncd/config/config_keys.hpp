// The one table of every INI key cncd interprets: its type, default, range, unit and meaning.
// load_machine_config reads values only through this table, so the ranges enforced and the
// help printed can never drift apart.
#pragma once

#include <span>
#include <string_view>

namespace cncd::config {

enum class KeyType {
  real,       // decimal number; nan/inf/out of double range are rejected
  integer,    // whole number (1000000 or 1e6)
  boolean,    // 1/0, TRUE/FALSE, YES/NO, ON/OFF, any case
  text,       // free text, kept verbatim
  path,       // file name, resolved relative to the INI file's directory
  path_list,  // colon-separated list of paths
  choice,     // one of `choices` (separated by '|'), any case
  signal,     // a signal address (gpio:LINE, modbus:BUS:SLAVE:coil|hr|di|ir:N, sim:NAME)
};

struct KeySpec {
  std::string_view
      section;  // "TRAJ"; "JOINT_n" / "AXIS_L" / "MODBUS_n" stand for every joint / axis / bus
  std::string_view key;  // a trailing "_n" stands for any number: "DIGITAL_OUTPUT_n"
  KeyType type;
  std::string_view default_value;  // as it would be written in the INI; empty: see help
  double min;                      // inclusive unless min_exclusive (real and integer only)
  double max;                      // inclusive
  bool min_exclusive;
  std::string_view unit;     // "ns", "s", "units/s" ... ("units" = LINEAR/ANGULAR_UNITS)
  std::string_view choices;  // for KeyType::choice
  std::string_view help;
};

std::span<const KeySpec> key_table();

// The spec for a key, with [JOINT_3] matched by "JOINT_n", [AXIS_Y] by "AXIS_L" and the key
// DIGITAL_OUTPUT_7 by "DIGITAL_OUTPUT_n" (whatever the number: the loader checks its range);
// nullptr when cncd does not interpret the key.
const KeySpec* find_key_spec(std::string_view section, std::string_view key);

// The table's name for a section ("JOINT_n" for [JOINT_3], "TRAJ" for [TRAJ]); empty when cncd
// interprets no key of that section.
std::string_view key_table_section(std::string_view section);

}  // namespace cncd::config
