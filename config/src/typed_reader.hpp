// Typed access to an IniFile through the key table (not installed). Every value is checked
// against its KeySpec; problems and warnings are collected, never thrown.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cncd/config/config_keys.hpp"
#include "cncd/config/ini_file.hpp"
#include "cncd/config/number_text.hpp"

namespace cncd::config {

class TypedReader {
 public:
  TypedReader(IniFile& ini, std::vector<Problem>& problems, std::vector<Problem>& warnings)
      : ini_(ini), problems_(problems), warnings_(warnings) {}

  // The value of the key, or the table default when the key is absent. nullopt when the key
  // is absent without a default, or when the value is invalid (a problem is then recorded).
  std::optional<double> real(std::string_view section, std::string_view key);
  std::optional<std::int64_t> integer(std::string_view section, std::string_view key);
  std::optional<bool> boolean(std::string_view section, std::string_view key);
  std::optional<std::string> text(std::string_view section, std::string_view key);
  // Paths are resolved against the INI file's directory; empty text gives an empty path.
  std::optional<std::filesystem::path> path(std::string_view section, std::string_view key);
  std::vector<std::filesystem::path> path_list(std::string_view section, std::string_view key);
  // The choice as the table spells it (the INI may use any case).
  std::optional<std::string> choice(std::string_view section, std::string_view key);
  // The signal address the key names (its source set); an absent or empty key gives an
  // address of kind none. With `bare_is_gpio`, a value without a kind ("17", "!17") is a
  // gpio line.
  SignalAddress signal(std::string_view section, std::string_view key, bool bare_is_gpio = false);
  // What a line key of [GPIO] or a step/dir joint names, with its *_ACTIVE_LOW key
  // (parse_gpio_line_key); nullopt when the key is absent or refused. The first call records the
  // refusal; later ones only give nullopt, so every check may ask.
  std::optional<GpioLineKey> gpio_line(std::string_view section, std::string_view key);

  // The first entry of the key (every one marked used), nullptr when absent.
  const IniEntry* entry(std::string_view section, std::string_view key);
  bool given(std::string_view section, std::string_view key) const {
    return ini_.find(section, key) != nullptr;
  }

  // Where a message about the key belongs: the key's line, else its section's header, else
  // the file itself.
  SourceRef where(std::string_view section, std::string_view key) const;
  void problem(std::string_view section, std::string_view key, std::string message);
  void warning(std::string_view section, std::string_view key, std::string message);

  // True when the key was given but its value was refused; cross-checks skip such keys so
  // that one bad value gives one problem.
  bool failed(std::string_view section, std::string_view key) const;

  const IniFile& ini() const { return ini_; }
  std::vector<Problem>& problems() { return problems_; }
  std::vector<Problem>& warnings() { return warnings_; }

 private:
  // The spec and the text to interpret (the INI value or the default), with its entry.
  struct Raw {
    const KeySpec* spec = nullptr;
    const IniEntry* entry = nullptr;
    std::string text;
  };
  std::optional<Raw> raw(std::string_view section, std::string_view key);
  bool check_range(const Raw& raw, std::string_view section, std::string_view key, double value);
  std::filesystem::path resolve(std::string_view text) const;

  IniFile& ini_;
  std::vector<std::pair<std::string, std::string>> failed_;
  std::vector<Problem>& problems_;
  std::vector<Problem>& warnings_;
};

}  // namespace cncd::config
