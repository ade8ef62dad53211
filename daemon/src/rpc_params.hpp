// The declared parameters of every method (methods_table.cpp), and the check the dispatcher
// makes against them before a handler runs: a request that names a parameter its method does
// not take, or gives one of the wrong type, is refused rather than half understood.
#pragma once

#include <limits>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace cncd::daemon {

// What a connection may do, from its peer credentials.
enum class Access { none, read, control };

enum class ParamType {
  integer,       // a JSON integer: 2, never 2.0 or 2e0
  number,        // any JSON number
  string,        // any JSON string
  string_list,   // an array of strings
  integer_list,  // an array of integers; the range applies to each
  axis_values,   // an object of axis letters and numbers, {"x": 1.5}; the handler checks them
  coord_system,  // "G54" .. "G59.3" or 1 .. 9; the handler checks which
};

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

struct ParamSpec {
  std::string_view name;
  ParamType type = ParamType::string;
  bool required = false;
  double min = -kUnbounded;  // integer, number, integer_list; inclusive
  double max = kUnbounded;
  std::string_view note;  // what the value means, shown in errors: "feed override ratio"
};

struct MethodSpec {
  std::string_view name;
  Access needs = Access::control;  // read: queries; control: commands
  std::vector<ParamSpec> params;
  // A request to a control method sent on behalf of someone is recorded in the event log; a
  // method that changes nothing (jog.heartbeat) is not.
  bool recorded = true;
};

// Every method cncd serves, with its parameters in the order errors list them.
const std::vector<MethodSpec>& method_table();

// "integer", "number", ... as docs/protocol.md's parameter table names the types.
std::string_view type_name(ParamType type);
// "an integer from 1 to 99999 (tool number)"
std::string describe(const ParamSpec& param);

// `text` as a JSON string, cut short: error messages quote names from requests of up to 1 MiB.
std::string quoted_text(std::string_view text);

// Checks a request's "params" (nullptr when it has none) against `method`. Returns the params
// as an object, optional parameters given as null left out, or the error message for -32602.
std::variant<nlohmann::json, std::string> check_params(const MethodSpec& method,
                                                       const nlohmann::json* params);

}  // namespace cncd::daemon
