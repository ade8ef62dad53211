#include "ini_lookup.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cncd/config/number_text.hpp"

namespace cncd::drivers {

std::string upper(std::string text) {
  for (char& c : text)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

namespace {

// LinuxCNC reads numbers with sscanf, so "25000  # ns" is 25000.
std::optional<double> parse_real(const std::string& text) {
  if (text.empty()) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || errno == ERANGE || !std::isfinite(value)) return std::nullopt;
  while (*end == ' ' || *end == '\t')
    ++end;
  if (*end != '\0' && *end != '#' && *end != ';') return std::nullopt;
  return value;
}

}  // namespace

std::string joint_section(int joint) {
  return "JOINT_" + std::to_string(joint);
}

bool IniLookup::has(std::string_view section, std::string_view key) const {
  return ini_ != nullptr && ini_->find(section, key) != nullptr;
}

std::optional<std::string> IniLookup::text(std::string_view section, std::string_view key) const {
  if (ini_ == nullptr) return std::nullopt;
  return ini_->value(section, key);
}

const config::KeySpec* IniLookup::spec(std::string_view section, std::string_view key) {
  const config::KeySpec* found = config::find_key_spec(section, key);
  if (found == nullptr) fail(section, key, "is not in the config key table");
  return found;
}

namespace {

double default_number(const config::KeySpec& spec) {
  return parse_real(std::string(spec.default_value)).value_or(0.0);
}

std::string range_text(const config::KeySpec& spec) {
  return "outside " + config::format_number(spec.min) + " .. " + config::format_number(spec.max);
}

bool in_range(const config::KeySpec& spec, double value) {
  const bool above_min = spec.min_exclusive ? value > spec.min : value >= spec.min;
  return above_min && value <= spec.max;
}

}  // namespace

double IniLookup::real(std::string_view section, std::string_view key) {
  const config::KeySpec* s = spec(section, key);
  if (s == nullptr) return 0.0;
  const double fallback = default_number(*s);
  const auto raw = text(section, key);
  if (!raw) return fallback;
  const auto value = parse_real(*raw);
  if (!value) {
    fail(section, key, "'" + *raw + "' is not a number");
    return fallback;
  }
  if (!in_range(*s, *value)) {
    fail(section, key, *raw + " is " + range_text(*s));
    return fallback;
  }
  return *value;
}

std::int64_t IniLookup::integer(std::string_view section, std::string_view key) {
  const config::KeySpec* s = spec(section, key);
  if (s == nullptr) return 0;
  const auto fallback = static_cast<std::int64_t>(default_number(*s));
  const auto raw = text(section, key);
  if (!raw) return fallback;
  const auto value = parse_real(*raw);
  if (!value || *value != std::floor(*value)) {
    fail(section, key, "'" + *raw + "' is not a whole number");
    return fallback;
  }
  if (!in_range(*s, *value)) {
    fail(section, key, *raw + " is " + range_text(*s));
    return fallback;
  }
  return static_cast<std::int64_t>(*value);
}

bool IniLookup::boolean(std::string_view section, std::string_view key) {
  const config::KeySpec* s = spec(section, key);
  if (s == nullptr) return false;
  const std::string d = upper(std::string(s->default_value));
  const bool fallback = d == "1" || d == "TRUE" || d == "YES" || d == "ON";
  const auto raw = text(section, key);
  if (!raw) return fallback;
  const std::string u = upper(*raw);
  if (u == "1" || u == "TRUE" || u == "YES" || u == "ON") return true;
  if (u == "0" || u == "FALSE" || u == "NO" || u == "OFF") return false;
  fail(section, key, "'" + *raw + "' is not a boolean (1/0, TRUE/FALSE, YES/NO, ON/OFF)");
  return fallback;
}

std::string IniLookup::choice(std::string_view section, std::string_view key) {
  const config::KeySpec* s = spec(section, key);
  if (s == nullptr) return "";
  const auto raw = text(section, key);
  if (!raw) return std::string(s->default_value);
  const std::string u = upper(*raw);
  std::string_view rest = s->choices;
  while (!rest.empty()) {
    const auto bar = rest.find('|');
    if (upper(std::string(rest.substr(0, bar))) == u) return *raw;
    rest = bar == std::string_view::npos ? std::string_view() : rest.substr(bar + 1);
  }
  fail(section, key, "'" + *raw + "' must be one of " + std::string(s->choices));
  return std::string(s->default_value);
}

void IniLookup::fail(std::string_view section, std::string_view key, const std::string& message) {
  if (!error_.empty()) return;
  config::Problem problem;
  problem.section = std::string(section);
  problem.key = std::string(key);
  problem.message = message;
  if (ini_ != nullptr) {
    if (const auto* entry = ini_->find(section, key)) {
      problem.file = entry->source.file;
      problem.line = entry->source.line;
    } else if (const auto* header = ini_->section(section)) {
      problem.file = header->source.file;
      problem.line = header->source.line;
    } else {
      problem.file = ini_->path().string();
    }
  }
  error_ = problem.to_string();
}

}  // namespace cncd::drivers
