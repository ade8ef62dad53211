// Raw INI lookups for driver keys (not installed). load_machine_config has already validated
// these keys against the key table; the drivers check again because a MachineConfig may be
// built by hand, and they report problems as FILE:LINE: [SECTION] KEY: message.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "cncd/config/ini_file.hpp"
#include "cncd/config/machine_config.hpp"

namespace cncd::drivers {

class IniLookup {
 public:
  explicit IniLookup(const config::MachineConfig& machine) : ini_(machine.ini.get()) {}

  bool has(std::string_view section, std::string_view key) const;
  std::optional<std::string> text(std::string_view section, std::string_view key) const;
  // Numbers: absent gives `fallback`; a bad value or one outside [min, max] sets error_.
  double real(std::string_view section, std::string_view key, double fallback, double min,
              double max);
  std::int64_t integer(std::string_view section, std::string_view key, std::int64_t fallback,
                       std::int64_t min, std::int64_t max);
  bool boolean(std::string_view section, std::string_view key, bool fallback);

  // Records the first problem, placed at the key's line when it exists.
  void fail(std::string_view section, std::string_view key, const std::string& message);
  const std::string& error() const { return error_; }

 private:
  const config::IniFile* ini_;
  std::string error_;
};

std::string joint_section(int joint);

}  // namespace cncd::drivers
