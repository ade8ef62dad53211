// Small text helpers shared by the INI reader and the typed loader (not installed).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace cncd::config {

std::string_view trim(std::string_view text);
bool iequals(std::string_view a, std::string_view b);
std::string to_lower(std::string_view text);
std::string to_upper(std::string_view text);

// The first byte that has no place in a text line (NUL, control characters other than tab).
std::optional<unsigned char> find_control_char(std::string_view line);
std::string hex_byte(unsigned char byte);
// The text shortened to a readable excerpt for messages.
std::string printable(std::string_view text);

// A value with a trailing "  # comment" or "  ; comment" removed; LinuxCNC reads numbers with
// sscanf and so ignores such comments, and real configs rely on it.
std::string_view strip_trailing_comment(std::string_view value);

enum class NumberError { none, empty, not_a_number, not_finite, out_of_range };
// Parses a whole decimal number ("12", "-0.5", "+1e3"); nan, inf and values beyond double
// range are refused.
NumberError parse_number(std::string_view text, double& out);
std::optional<bool> parse_bool(std::string_view text);

}  // namespace cncd::config
