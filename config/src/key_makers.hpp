// The makers of config_keys.cpp's table entries: one per kind of key, each with the type,
// range and unit that kind always has.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

#include "cncd/config/config_keys.hpp"

namespace cncd::config::key_makers {

constexpr double kInf = 1e308;
constexpr double kBig = 1e99;  // LinuxCNC writes +-1e99 for "no soft limit"

constexpr KeySpec text_key(std::string_view section, std::string_view key,
                           std::string_view default_value, std::string_view help) {
  return {section, key, KeyType::text, default_value, 0, 0, false, "", "", help};
}

constexpr KeySpec path_key(std::string_view section, std::string_view key,
                           std::string_view default_value, std::string_view help) {
  return {section, key, KeyType::path, default_value, 0, 0, false, "", "", help};
}

// Lists have no default: an empty list.
constexpr KeySpec path_list_key(std::string_view section, std::string_view key,
                                std::string_view help) {
  return {section, key, KeyType::path_list, "", 0, 0, false, "", "", help};
}

constexpr KeySpec bool_key(std::string_view section, std::string_view key,
                           std::string_view default_value, std::string_view help) {
  return {section, key, KeyType::boolean, default_value, 0, 0, false, "", "", help};
}

constexpr KeySpec choice_key(std::string_view section, std::string_view key,
                             std::string_view default_value, std::string_view choices,
                             std::string_view help, std::string_view unit = "") {
  return {section, key, KeyType::choice, default_value, 0, 0, false, unit, choices, help};
}

constexpr KeySpec integer_key(std::string_view section, std::string_view key,
                              std::string_view default_value, double min, double max,
                              std::string_view unit, std::string_view help) {
  return {section, key, KeyType::integer, default_value, min, max, false, unit, "", help};
}

constexpr KeySpec real_key(std::string_view section, std::string_view key,
                           std::string_view default_value, double min, double max,
                           std::string_view unit, std::string_view help) {
  return {section, key, KeyType::real, default_value, min, max, false, unit, "", help};
}

// Line of a GPIO input or output: a bare line (offset or name) or a gpio: address
// (parse_gpio_line_key); empty: none.
constexpr KeySpec line_key(std::string_view section, std::string_view key, std::string_view help) {
  return text_key(section, key, "", help);
}

constexpr KeySpec active_low_key(std::string_view section, std::string_view key,
                                 std::string_view help) {
  return bool_key(section, key, "0", help);
}

// A position in machine units; LinuxCNC's +-1e99 stands for "anywhere".
constexpr KeySpec position_key(std::string_view section, std::string_view key,
                               std::string_view default_value, std::string_view help) {
  return real_key(section, key, default_value, -kBig, kBig, "units", help);
}

// A step/dir timing in ns, one base period at the least.
constexpr KeySpec step_timing_key(std::string_view section, std::string_view key,
                                  std::string_view help) {
  return integer_key(section, key, "1", 0, 100'000'000, "ns", help);
}

// A Modbus register address.
constexpr KeySpec register_key(std::string_view section, std::string_view key,
                               std::string_view default_value, std::string_view help) {
  return integer_key(section, key, default_value, 0, 65535, "", help);
}

// A signal address (docs/drivers.md, "Signal addresses"); empty: not connected.
constexpr KeySpec signal_key(std::string_view section, std::string_view key,
                             std::string_view help) {
  return {section, key, KeyType::signal, "", 0, 0, false, "", "", help};
}

// A real number that must be above zero: a velocity, an acceleration, a following error.
constexpr KeySpec positive_key(std::string_view section, std::string_view key,
                               std::string_view default_value, std::string_view unit,
                               std::string_view help) {
  return {section, key, KeyType::real, default_value, 0, kInf, true, unit, "", help};
}

// Where a key's axis letter placeholder is: the L of "JOG_L_PLUS" and "MPG_AXIS_L" (4, 9),
// which stands for any axis letter; npos for a key without one.
constexpr std::size_t axis_placeholder(std::string_view key) {
  const std::size_t at = key.find("_L");
  if (at == std::string_view::npos || (at + 2 != key.size() && key[at + 2] != '_')) {
    return std::string_view::npos;
  }
  return at + 1;
}

// `a` then `b`, as one array.
template <std::size_t N, std::size_t M>
constexpr std::array<KeySpec, N + M> join_keys(const std::array<KeySpec, N>& a,
                                               const std::array<KeySpec, M>& b) {
  std::array<KeySpec, N + M> all{};
  for (std::size_t i = 0; i < N; ++i)
    all[i] = a[i];
  for (std::size_t i = 0; i < M; ++i)
    all[N + i] = b[i];
  return all;
}

}  // namespace cncd::config::key_makers
