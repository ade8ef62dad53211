#include "ini_lookup.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace cncd::drivers {
namespace {

std::string upper(std::string text) {
  for (char& c : text)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

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

double IniLookup::real(std::string_view section, std::string_view key, double fallback, double min,
                       double max) {
  const auto raw = text(section, key);
  if (!raw) return fallback;
  const auto value = parse_real(*raw);
  if (!value) {
    fail(section, key, "'" + *raw + "' is not a number");
    return fallback;
  }
  if (*value < min || *value > max) {
    fail(section, key, *raw + " is outside " + std::to_string(min) + " .. " + std::to_string(max));
    return fallback;
  }
  return *value;
}

std::int64_t IniLookup::integer(std::string_view section, std::string_view key,
                                std::int64_t fallback, std::int64_t min, std::int64_t max) {
  const auto raw = text(section, key);
  if (!raw) return fallback;
  const auto value = parse_real(*raw);
  if (!value || *value != std::floor(*value)) {
    fail(section, key, "'" + *raw + "' is not a whole number");
    return fallback;
  }
  if (*value < static_cast<double>(min) || *value > static_cast<double>(max)) {
    fail(section, key, *raw + " is outside " + std::to_string(min) + " .. " + std::to_string(max));
    return fallback;
  }
  return static_cast<std::int64_t>(*value);
}

bool IniLookup::boolean(std::string_view section, std::string_view key, bool fallback) {
  const auto raw = text(section, key);
  if (!raw) return fallback;
  const std::string u = upper(*raw);
  if (u == "1" || u == "TRUE" || u == "YES" || u == "ON") return true;
  if (u == "0" || u == "FALSE" || u == "NO" || u == "OFF") return false;
  fail(section, key, "'" + *raw + "' is not a boolean (1/0, TRUE/FALSE, YES/NO, ON/OFF)");
  return fallback;
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
