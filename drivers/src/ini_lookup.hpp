// Raw INI lookups for driver keys (not installed). load_machine_config has already validated
// these keys against the key table; the drivers check again because a MachineConfig may be
// built by hand, and they report problems as FILE:LINE: [SECTION] KEY: message.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "cncd/config/config_keys.hpp"
#include "cncd/config/ini_file.hpp"
#include "cncd/config/machine_config.hpp"

namespace cncd::drivers {

class IniLookup {
 public:
  explicit IniLookup(const config::MachineConfig& machine) : ini_(machine.ini.get()) {}

  bool has(std::string_view section, std::string_view key) const;
  std::optional<std::string> text(std::string_view section, std::string_view key) const;
  // Keys of the config key table (config::find_key_spec): an absent key gives the table's
  // default (0, false or "" when it has none: the caller checks required keys with has()); a
  // value of the wrong type, or outside the table's range or choices, records a problem and
  // gives the default. A key missing from the table is a problem too, so that the table stays
  // the one list of keys, defaults and ranges that validation, docs and --check-config show.
  double real(std::string_view section, std::string_view key);
  std::int64_t integer(std::string_view section, std::string_view key);
  bool boolean(std::string_view section, std::string_view key);
  // A choice key's value as written (any case), or its default.
  std::string choice(std::string_view section, std::string_view key);

  // Records the first problem, placed at the key's line when it exists.
  void fail(std::string_view section, std::string_view key, const std::string& message);
  const std::string& error() const { return error_; }

 private:
  // The key's spec, or nullptr after recording that the table lacks it.
  const config::KeySpec* spec(std::string_view section, std::string_view key);

  const config::IniFile* ini_;
  std::string error_;
};

std::string joint_section(int joint);

// `text` in ASCII upper case: choice values are compared in any case.
std::string upper(std::string text);

}  // namespace cncd::drivers
