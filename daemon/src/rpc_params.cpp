#include "rpc_params.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <utility>

namespace cncd::daemon {

using nlohmann::json;

namespace {

// Values and names quoted in messages are cut short: a request may carry 1 MiB of them.
constexpr std::size_t kShownChars = 60;

std::string shown(const json& value) {
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > kShownChars) text = text.substr(0, kShownChars) + "...";
  return text;
}

// 1, 1.5, 100000000: as written in the protocol's documentation, never 1e+08.
std::string number_text(double value) {
  if (std::abs(value) < 1e15 && value == std::floor(value)) {
    return std::to_string(static_cast<std::int64_t>(value));
  }
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

bool has_range(ParamType type) {
  return type == ParamType::integer || type == ParamType::number || type == ParamType::integer_list;
}

std::string_view kind(const json& value) {
  static constexpr std::pair<json::value_t, std::string_view> kKinds[] = {
      {json::value_t::array, "an array"},  {json::value_t::object, "an object"},
      {json::value_t::string, "a string"}, {json::value_t::boolean, "a boolean"},
      {json::value_t::null, "null"},
  };
  for (const auto& [type, words] : kKinds) {
    if (value.type() == type) return words;
  }
  return "a number";
}

// How the method help and the refusals speak of each parameter type.
struct TypeWords {
  ParamType type;
  std::string_view name;       // "array of strings"
  std::string_view described;  // "an array of strings", with what it looks like where unclear
};

constexpr TypeWords kTypeWords[] = {
    {ParamType::integer, "integer", "an integer"},
    {ParamType::number, "number", "a number"},
    {ParamType::string, "string", "a string"},
    {ParamType::string_list, "array of strings", "an array of strings"},
    {ParamType::integer_list, "array of integers", "an array of integers"},
    {ParamType::axis_values, "object of axis values",
     "an object of axis values such as {\"x\": 1.5}"},
    {ParamType::coord_system, "string or integer",
     "a coordinate system, \"G54\" .. \"G59.3\" or 1 .. 9"},
};

const TypeWords* words_of(ParamType type) {
  for (const auto& words : kTypeWords) {
    if (words.type == type) return &words;
  }
  return nullptr;
}

bool in_range(const ParamSpec& param, const json& number) {
  const double v = number.get<double>();
  return v >= param.min && v <= param.max;
}

// The one message for a value of the wrong type or outside the range.
std::string wrong_value(const ParamSpec& param, const json& value) {
  std::string message = "parameter " + quoted_text(param.name) + " must be " + describe(param) +
                        ", not " + shown(value);
  if (value.is_number_float() && value.get<double>() == std::floor(value.get<double>()) &&
      (param.type == ParamType::integer || param.type == ParamType::coord_system)) {
    message += " (an integer is written without a fraction or exponent)";
  }
  return message;
}

// A list shown cut short is followed by the item at fault.
std::string wrong_item(const ParamSpec& param, const json& list, const json& item) {
  std::string message = wrong_value(param, list);
  if (message.ends_with("...")) message += " (it holds " + shown(item) + ")";
  return message;
}

// "" when `value` is what `param` takes.
std::string check_value(const ParamSpec& param, const json& value) {
  switch (param.type) {
    case ParamType::integer:
      if (!value.is_number_integer()) return wrong_value(param, value);
      return in_range(param, value) ? "" : wrong_value(param, value);
    case ParamType::number:
      if (!value.is_number()) return wrong_value(param, value);
      return in_range(param, value) ? "" : wrong_value(param, value);
    case ParamType::string:
      return value.is_string() ? "" : wrong_value(param, value);
    case ParamType::string_list:
      if (!value.is_array()) return wrong_value(param, value);
      for (const auto& item : value) {
        if (!item.is_string()) return wrong_item(param, value, item);
      }
      return "";
    case ParamType::integer_list:
      if (!value.is_array()) return wrong_value(param, value);
      for (const auto& item : value) {
        if (!item.is_number_integer() || !in_range(param, item)) {
          return wrong_item(param, value, item);
        }
      }
      return "";
    case ParamType::axis_values:
      return value.is_object() ? "" : wrong_value(param, value);
    case ParamType::coord_system:
      return value.is_string() || value.is_number_integer() ? "" : wrong_value(param, value);
  }
  return wrong_value(param, value);
}

std::string parameter_names(const MethodSpec& method) {
  if (method.params.empty()) return std::string(method.name) + " takes no parameters";
  std::string text = std::string(method.name) + " takes: ";
  for (std::size_t i = 0; i < method.params.size(); ++i) {
    if (i > 0) text += ", ";
    text += method.params[i].name;
  }
  return text;
}

std::string parameter_descriptions(const MethodSpec& method) {
  if (method.params.empty()) return std::string(method.name) + " takes no parameters";
  std::string text = std::string(method.name) + " takes: ";
  for (std::size_t i = 0; i < method.params.size(); ++i) {
    const ParamSpec& param = method.params[i];
    if (i > 0) text += "; ";
    text += quoted_text(param.name) + ", " + describe(param) + (param.required ? ", required" : "");
  }
  return text;
}

}  // namespace

std::string quoted_text(std::string_view text) {
  const bool cut = text.size() > kShownChars;
  const std::string shown_text = json(std::string(text.substr(0, kShownChars)))
                                     .dump(-1, ' ', false, json::error_handler_t::replace);
  return cut ? shown_text.substr(0, shown_text.size() - 1) + "...\"" : shown_text;
}

std::string_view type_name(ParamType type) {
  const TypeWords* words = words_of(type);
  return words != nullptr ? words->name : "?";
}

std::string describe(const ParamSpec& param) {
  const TypeWords* words = words_of(param.type);
  std::string text = words != nullptr ? std::string(words->described) : std::string();
  if (has_range(param.type)) {
    const bool low = std::isfinite(param.min);
    const bool high = std::isfinite(param.max);
    if (low && high) {
      text += " from " + number_text(param.min) + " to " + number_text(param.max);
    } else if (low) {
      text += " of at least " + number_text(param.min);
    } else if (high) {
      text += " of at most " + number_text(param.max);
    }
  }
  if (!param.note.empty()) text += " (" + std::string(param.note) + ")";
  return text;
}

std::variant<json, std::string> check_params(const MethodSpec& method, const json* params) {
  static const json none = json::object();
  // An empty array is an empty list of positional parameters: nothing said.
  if (params == nullptr || params->is_null() || (params->is_array() && params->empty())) {
    params = &none;
  }
  if (!params->is_object()) {
    return "params must be an object of named parameters, not " + std::string(kind(*params)) +
           "; " + parameter_descriptions(method);
  }
  for (const auto& [key, value] : params->items()) {
    bool known = false;
    for (const auto& param : method.params)
      known = known || param.name == key;
    if (!known)
      return "unknown parameter " + quoted_text(key) + " (" + parameter_names(method) + ")";
  }
  json checked = json::object();
  for (const auto& param : method.params) {
    const auto it = params->find(param.name);
    if (it == params->end() || (it->is_null() && !param.required)) continue;
    if (auto error = check_value(param, *it); !error.empty()) return error;
    checked[std::string(param.name)] = *it;
  }
  for (const auto& param : method.params) {
    if (param.required && !checked.contains(param.name)) {
      return "parameter " + quoted_text(param.name) + " is missing; it must be " + describe(param);
    }
  }
  return checked;
}

}  // namespace cncd::daemon
