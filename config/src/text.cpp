#include "text.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <system_error>

namespace cncd::config {

std::string_view trim(std::string_view text) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  while (!text.empty() && blank(text.front()))
    text.remove_prefix(1);
  while (!text.empty() && blank(text.back()))
    text.remove_suffix(1);
  return text;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string to_lower(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string to_upper(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::optional<unsigned char> find_control_char(std::string_view line) {
  for (const char c : line) {
    const auto byte = static_cast<unsigned char>(c);
    if ((byte < 0x20 && byte != '\t' && byte != '\r') || byte == 0x7f) return byte;
  }
  return std::nullopt;
}

std::string hex_byte(unsigned char byte) {
  constexpr char kDigits[] = "0123456789abcdef";
  return std::string("0x") + kDigits[byte >> 4] + kDigits[byte & 0xf];
}

std::string printable(std::string_view text) {
  constexpr std::size_t kMax = 60;
  std::string out;
  for (const char c : text.substr(0, kMax)) {
    const auto byte = static_cast<unsigned char>(c);
    out += (byte < 0x20 || byte == 0x7f) ? '?' : c;
  }
  if (text.size() > kMax) out += "...";
  return out;
}

std::string_view strip_trailing_comment(std::string_view value) {
  for (std::size_t i = 1; i < value.size(); ++i) {
    if ((value[i] == '#' || value[i] == ';') && (value[i - 1] == ' ' || value[i - 1] == '\t')) {
      return trim(value.substr(0, i));
    }
  }
  return trim(value);
}

NumberError parse_number(std::string_view text, double& out) {
  text = trim(text);
  if (text.empty()) return NumberError::empty;
  if (text.front() == '+') text.remove_prefix(1);
  // from_chars accepts "nan" and "inf"; refuse them by shape before converting.
  const char first = text.empty() ? '\0' : text.front();
  const char second = text.size() > 1 ? text[1] : '\0';
  const bool digit_start =
      std::isdigit(static_cast<unsigned char>(first)) != 0 ||
      (first == '.' && std::isdigit(static_cast<unsigned char>(second))) ||
      (first == '-' && (std::isdigit(static_cast<unsigned char>(second)) || second == '.'));
  if (!digit_start) {
    const std::string lower = to_lower(text);
    if (lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos) {
      return NumberError::not_finite;
    }
    return NumberError::not_a_number;
  }
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec == std::errc::result_out_of_range) return NumberError::out_of_range;
  if (ec != std::errc() || end != text.data() + text.size()) return NumberError::not_a_number;
  if (!std::isfinite(value)) return NumberError::not_finite;
  out = value;
  return NumberError::none;
}

std::optional<bool> parse_bool(std::string_view text) {
  text = trim(text);
  for (const auto yes : {"1", "TRUE", "YES", "ON"}) {
    if (iequals(text, yes)) return true;
  }
  for (const auto no : {"0", "FALSE", "NO", "OFF"}) {
    if (iequals(text, no)) return false;
  }
  return std::nullopt;
}

}  // namespace cncd::config
