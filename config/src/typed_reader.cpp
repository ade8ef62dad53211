#include "typed_reader.hpp"

#include <cmath>
#include <cstdio>

#include "text.hpp"

namespace cncd::config {

std::string format_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

std::optional<TypedReader::Raw> TypedReader::raw(std::string_view section, std::string_view key) {
  Raw result;
  result.spec = find_key_spec(section, key);
  result.entry = entry(section, key);
  if (result.entry != nullptr) {
    result.text = result.entry->value;
    return result;
  }
  if (result.spec == nullptr || result.spec->default_value.empty()) return std::nullopt;
  result.text = result.spec->default_value;
  return result;
}

const IniEntry* TypedReader::entry(std::string_view section, std::string_view key) {
  const auto all = ini_.find_all(section, key);
  if (all.empty()) return nullptr;
  // A repeated key is reported once by check_keys.
  for (const IniEntry* e : all)
    ini_.mark_used(*e);
  return all.front();
}

SourceRef TypedReader::where(std::string_view section, std::string_view key) const {
  if (const IniEntry* e = ini_.find(section, key)) return e->source;
  if (const IniSection* s = ini_.section(section)) return s->source;
  return SourceRef{ini_.path().lexically_normal().string(), 0};
}

bool TypedReader::failed(std::string_view section, std::string_view key) const {
  for (const auto& [s, k] : failed_) {
    if (s == section && k == key) return true;
  }
  return false;
}

void TypedReader::problem(std::string_view section, std::string_view key, std::string message) {
  failed_.emplace_back(section, key);
  const SourceRef at = where(section, key);
  problems_.push_back(
      Problem{at.file, at.line, std::string(section), std::string(key), std::move(message)});
}

void TypedReader::warning(std::string_view section, std::string_view key, std::string message) {
  const SourceRef at = where(section, key);
  warnings_.push_back(
      Problem{at.file, at.line, std::string(section), std::string(key), std::move(message)});
}

bool TypedReader::check_range(const Raw& r, std::string_view section, std::string_view key,
                              double value) {
  if (r.spec == nullptr) return true;
  const auto& s = *r.spec;
  const bool low = s.min_exclusive ? value <= s.min : value < s.min;
  if (!low && value <= s.max) return true;
  const std::string unit = s.unit.empty() ? "" : " " + std::string(s.unit);
  std::string rule;
  if (s.max >= 1e300) {
    rule = (s.min_exclusive ? "must be greater than " : "must be at least ") +
           format_number(s.min) + unit;
  } else {
    rule = "must be between " + format_number(s.min) + " and " + format_number(s.max) + unit;
  }
  problem(section, key, r.text + " is out of range: " + rule);
  return false;
}

std::optional<double> TypedReader::real(std::string_view section, std::string_view key) {
  const auto r = raw(section, key);
  if (!r) return std::nullopt;
  double value = 0;
  switch (parse_number(strip_trailing_comment(r->text), value)) {
    case NumberError::none:
      break;
    case NumberError::empty:
      problem(section, key, "value is empty; expected a number");
      return std::nullopt;
    case NumberError::not_finite:
      problem(section, key, "'" + printable(r->text) + "' is not a finite number");
      return std::nullopt;
    case NumberError::out_of_range:
      problem(section, key, "'" + printable(r->text) + "' is too large or too small a number");
      return std::nullopt;
    case NumberError::not_a_number:
      problem(section, key, "'" + printable(r->text) + "' is not a number");
      return std::nullopt;
  }
  if (!check_range(*r, section, key, value)) return std::nullopt;
  return value;
}

std::optional<std::int64_t> TypedReader::integer(std::string_view section, std::string_view key) {
  const auto value = real(section, key);
  if (!value) return std::nullopt;
  if (std::trunc(*value) != *value || std::fabs(*value) > 9e15) {
    problem(section, key,
            "'" + printable(ini_.value(section, key).value_or("")) + "' is not a whole number");
    return std::nullopt;
  }
  return static_cast<std::int64_t>(*value);
}

std::optional<bool> TypedReader::boolean(std::string_view section, std::string_view key) {
  const auto r = raw(section, key);
  if (!r) return std::nullopt;
  const auto value = parse_bool(strip_trailing_comment(r->text));
  if (!value) {
    problem(section, key,
            "'" + printable(r->text) + "' is not a yes/no value (use 1/0, YES/NO, TRUE/FALSE)");
  }
  return value;
}

std::optional<std::string> TypedReader::text(std::string_view section, std::string_view key) {
  const auto r = raw(section, key);
  if (!r) return std::nullopt;
  return r->text;
}

std::filesystem::path TypedReader::resolve(std::string_view text) const {
  if (text.empty()) return {};
  std::filesystem::path p(text);
  if (p.is_relative()) p = ini_.directory() / p;
  return p.lexically_normal();
}

std::optional<std::filesystem::path> TypedReader::path(std::string_view section,
                                                       std::string_view key) {
  const auto r = raw(section, key);
  if (!r) return std::nullopt;
  return resolve(r->text);
}

std::vector<std::filesystem::path> TypedReader::path_list(std::string_view section,
                                                          std::string_view key) {
  std::vector<std::filesystem::path> paths;
  const auto r = raw(section, key);
  if (!r) return paths;
  std::string_view rest = r->text;
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::string_view item = trim(rest.substr(0, colon));
    if (!item.empty()) paths.push_back(resolve(item));
    if (colon == std::string_view::npos) break;
    rest.remove_prefix(colon + 1);
  }
  return paths;
}

std::optional<std::string> TypedReader::choice(std::string_view section, std::string_view key) {
  const auto r = raw(section, key);
  if (!r) return std::nullopt;
  const std::string_view value = strip_trailing_comment(r->text);
  std::string_view choices = r->spec != nullptr ? r->spec->choices : "";
  std::string allowed;
  while (!choices.empty()) {
    const std::size_t bar = choices.find('|');
    const std::string_view option = choices.substr(0, bar);
    if (iequals(option, value)) return std::string(option);
    allowed += (allowed.empty() ? "" : ", ") + std::string(option);
    if (bar == std::string_view::npos) break;
    choices.remove_prefix(bar + 1);
  }
  problem(section, key, "unknown value '" + printable(value) + "'; expected one of " + allowed);
  return std::nullopt;
}

SignalAddress TypedReader::signal(std::string_view section, std::string_view key,
                                  bool bare_is_gpio) {
  SignalAddress address;
  const IniEntry* e = entry(section, key);
  if (e == nullptr) return address;
  std::string written(trim(strip_trailing_comment(e->value)));
  if (written.empty()) return address;
  if (bare_is_gpio && written.find(':') == std::string::npos) {
    written = (written.starts_with('!') ? "gpio:!" + written.substr(1) : "gpio:" + written);
  }
  if (const std::string error = parse_signal_address(written, address); !error.empty()) {
    problem(section, key, "'" + printable(e->value) + "': " + error);
    return SignalAddress{};
  }
  address.text = std::string(trim(strip_trailing_comment(e->value)));
  address.source = e->source;
  return address;
}

std::optional<GpioLineKey> TypedReader::gpio_line(std::string_view section, std::string_view key) {
  const IniEntry* e = entry(section, key);
  if (e == nullptr || failed(section, key)) return std::nullopt;
  // A bad *_ACTIVE_LOW value is its own key's problem (boolean()); here it counts as not given.
  std::optional<bool> active_low;
  if (const std::string low_key = line_active_low_key(key); !low_key.empty()) {
    if (const auto v = ini_.value(section, low_key))
      active_low = parse_bool(strip_trailing_comment(*v));
  }
  GpioLineKey line;
  const std::string error = parse_gpio_line_key(key, e->value, active_low, line);
  if (error.empty()) return line;
  problem(section, key, error);
  return std::nullopt;
}

}  // namespace cncd::config
