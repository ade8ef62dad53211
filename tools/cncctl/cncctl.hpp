// cncctl's commands, shared between its source files.
//
// Exit status: 0 done, 1 failed (the program or the machine reported a failure), 2 refused
// (cncd declined the request: state, permission, bad value), 64 usage, 69 cncd not reachable
// or the connection lost.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "client.hpp"

namespace cncd::cncctl {

constexpr int kDone = 0;
constexpr int kFailed = 1;
constexpr int kRefused = 2;
constexpr int kUsage = 64;
constexpr int kUnavailable = 69;

// cncd answered with an error object.
struct Refused {
  std::string message;
  int code = 0;  // the JSON-RPC error code
};
// The command line is wrong.
struct UsageError {
  std::string message;
};

using Args = std::vector<std::string>;

// Text from cncd (a program's MSG, errors, events, file names) as it may go to a terminal:
// printable UTF-8 as it is; tab, newline and return as \t \n \r; other C0 controls, DEL and
// bytes that are not UTF-8 as \xNN; the C1 controls U+0080-U+009F as \u0080-\u009f.
std::string printable(std::string_view text);
// object[key] through printable(); "" when it is not a string.
std::string text_field(const nlohmann::json& object, const char* key);

// The response's result; throws Refused when it holds an error.
nlohmann::json result_of(const nlohmann::json& response);
// "X 1.0000  Y 2.0000  Z 3.0000"
std::string axes_text(const nlohmann::json& axes);
// A number from the command line; throws UsageError naming `what`.
double number_arg(const std::string& text, const std::string& what);
// The status as readable lines.
void print_status(const nlohmann::json& s);
// What `method` answers: pretty JSON with --json, else as `print` writes it. Returns kDone.
int show(daemon::Client& client, const char* method, bool json_output,
         void (*print)(const nlohmann::json&));

// `watch [--interval MS] [--count N]`
int watch(daemon::Client& client, const Args& args, bool json_output);
// `tools` and `tools set T<n> [P..] [X..W..] [D..] [I..] [J..] [Q..] [;comment]`
int tools(daemon::Client& client, const Args& args, bool json_output);
// `offsets` and `offsets set G54..G59.3 [X..W..] [R..]`
int offsets(daemon::Client& client, const Args& args, bool json_output);

// `jobs [stats] [--since YYYY-MM-DD] [--limit N]`: jobs.history, jobs.stats
int jobs(daemon::Client& client, const Args& args, bool json_output);
// `info`: system.info
int info(daemon::Client& client, const Args& args, bool json_output);
// `override feed|rapid|spindle PERCENT`
int override_command(daemon::Client& client, const Args& args, bool json_output);

// `jog AXIS +/-VELOCITY`, `jog AXIS --increment DIST [--velocity V]`, `jog AXIS stop`
int jog(daemon::Client& client, const Args& args, bool json_output);

}  // namespace cncd::cncctl
