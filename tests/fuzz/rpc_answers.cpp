#include "rpc_answers.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <set>

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include "rpc.hpp"

namespace cncd::fuzz {

using daemon::Access;
using nlohmann::json;

namespace {

// The dispatcher's limits (rpc.cpp), as docs/protocol.md states them.
constexpr int kMaxNesting = 64;
constexpr std::size_t kMaxBatch = 256;

const daemon::MethodSpec* find_method(const std::string& name) {
  for (const auto& method : daemon::method_table()) {
    if (method.name == name) return &method;
  }
  return nullptr;
}

// Levels of arrays and objects, as the dispatcher counts brackets outside strings.
int depth(const json& value) {
  if (!value.is_structured()) return 0;
  int deepest = 0;
  for (const auto& item : value)
    deepest = std::max(deepest, depth(item));
  return deepest + 1;
}

Request request_of(const json& value) {
  Request request;
  if (!value.is_object()) return request;  // answered with an error and a null id
  const auto id = value.find("id");
  request.answered = id != value.end();
  if (request.answered) request.id = *id;
  const auto method = value.find("method");
  if (method != value.end() && method->is_string()) {
    request.method = method->get<std::string>();
    const auto* spec = find_method(request.method);
    request.control = spec != nullptr && spec->needs == Access::control;
  }
  return request;
}

bool known_code(int code) {
  static const std::set<int> codes = {daemon::kParseError,
                                      daemon::kInvalidRequest,
                                      daemon::kMethodNotFound,
                                      daemon::kInvalidParams,
                                      daemon::kInternalError,
                                      daemon::kWrongState,
                                      daemon::kNotHomed,
                                      daemon::kProgramError,
                                      daemon::kBusy,
                                      daemon::kPermissionDenied,
                                      daemon::kRequestTooLarge,
                                      daemon::kFileError,
                                      daemon::kFault,
                                      daemon::kCancelled,
                                      daemon::kAttributionRefused,
                                      daemon::kUnavailable};
  return codes.contains(code);
}

// What is wrong with an error, "" when nothing.
std::string code_problem(int code, const std::string& message) {
  if (code == daemon::kInternalError)
    return "internal error: a handler failed on a request its parameter table let through";
  if (!known_code(code)) return "error code " + std::to_string(code) + " is not documented";
  if (message.empty()) return "an error without a message";
  return "";
}

// The error code of a well-formed response, 0 for a result.
int check_response(const json& response, const std::string& line, const std::string& answer) {
  if (!response.is_object() || response.size() != 3 || !response.contains("jsonrpc") ||
      response["jsonrpc"] != "2.0")
    fail("a response must be an object of \"jsonrpc\":\"2.0\", \"id\" and one result or error",
         line, answer);
  const auto id = response.find("id");
  if (id == response.end() || !(id->is_null() || id->is_string() || id->is_number()))
    fail("a response's id must be a string, a number or null", line, answer);
  if (response.contains("result")) return 0;
  const auto error = response.find("error");
  if (error == response.end() || !error->is_object() || error->size() != 2 ||
      !error->contains("code") || !(*error)["code"].is_number_integer() ||
      !error->contains("message") || !(*error)["message"].is_string())
    fail("an error must be an object of an integer code and a message", line, answer);
  const int code = (*error)["code"].get<int>();
  if (const auto problem = code_problem(code, (*error)["message"].get<std::string>());
      !problem.empty())
    fail(problem, line, answer);
  return code;
}

// One request's response: the request's id, or null when the id itself was at fault.
void match(Request& request, const json& response, const std::string& line,
           const std::string& answer) {
  const int code = check_response(response, line, answer);
  if (response["id"] != request.id &&
      !(response["id"].is_null() && code == daemon::kInvalidRequest))
    fail("the response does not carry the request's id", line, answer);
  if (code == daemon::kParseError) fail("a parse error for a request that parsed", line, answer);
  if (code == daemon::kMethodNotFound && find_method(request.method) != nullptr)
    fail("a method of the table was not found", line, answer);
  request.answer_error = code != 0;
  request.answer_code = code;
}

}  // namespace

[[noreturn]] void fail(const std::string& what, const std::string& line,
                       const std::string& answer) {
  constexpr std::size_t kShown = 600;
  std::fprintf(stderr, "rpc_fuzz: %s\n  request: %s\n  answer:  %s\n", what.c_str(),
               line.substr(0, kShown).c_str(), answer.substr(0, kShown).c_str());
  // The daemon's last errors (rpc_fuzz.cpp keeps them), e.g. what a failing handler threw.
  for (const auto& sink : spdlog::default_logger()->sinks()) {
    if (const auto ring = std::dynamic_pointer_cast<spdlog::sinks::ringbuffer_sink_mt>(sink)) {
      for (const auto& entry : ring->last_formatted())
        std::fprintf(stderr, "  log:     %s", entry.c_str());
    }
  }
  std::abort();
}

Expectation expect(const std::string& line) {
  Expectation expected;
  expected.parsed = json::parse(line, nullptr, /*allow_exceptions=*/false);
  expected.valid_json = !expected.parsed.is_discarded();
  if (!expected.valid_json || depth(expected.parsed) > kMaxNesting) {
    expected.line_error = true;
    return expected;
  }
  if (!expected.parsed.is_array()) {
    expected.requests.push_back(request_of(expected.parsed));
    return expected;
  }
  if (expected.parsed.empty() || expected.parsed.size() > kMaxBatch) {
    expected.line_error = true;
    return expected;
  }
  expected.batch = true;
  for (const auto& element : expected.parsed)
    expected.requests.push_back(request_of(element));
  return expected;
}

void check_completion(int error_code, const std::string& message, const json& id) {
  if (error_code == 0) return;
  if (const auto problem = code_problem(error_code, message); !problem.empty())
    fail(problem, "(answered later) id " + id.dump(), message);
}

void check_answer(const std::string& line, const std::optional<std::string>& answer,
                  Expectation& expected, const std::vector<json>& deferred_ids) {
  const bool lone = !expected.line_error && !expected.batch;
  if (!deferred_ids.empty() &&
      !(lone && !answer && expected.requests[0].answered && deferred_ids.size() == 1 &&
        deferred_ids[0] == expected.requests[0].id))
    fail("a request was filed to be answered later that is not the line's lone request", line,
         answer.value_or("(none)"));
  if (!answer) {
    if (expected.line_error) fail("no answer to a line refused as a whole", line, "(none)");
    for (auto& request : expected.requests) {
      if (request.answered && deferred_ids.empty())
        fail("a request with an id got no answer", line, "(none)");
      request.deferred = request.answered;
    }
    return;
  }
  if (answer->find_first_of("\r\n") != std::string::npos)
    fail("the answer holds a line break, which would cut it in two", line, *answer);
  const json parsed = json::parse(*answer, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) fail("the answer is not JSON", line, *answer);
  if (expected.line_error) {
    const int code = check_response(parsed, line, *answer);
    const bool refused =
        code == daemon::kInvalidRequest || (code == daemon::kParseError && !expected.valid_json);
    if (!refused || !parsed["id"].is_null())
      fail("a line refused as a whole needs one error with a null id", line, *answer);
    return;
  }
  if (!expected.batch) {
    if (!expected.requests[0].answered) fail("a notification was answered", line, *answer);
    match(expected.requests[0], parsed, line, *answer);
    return;
  }
  if (!parsed.is_array() || parsed.empty())
    fail("a batch is answered with a non-empty array", line, *answer);
  std::size_t next = 0;
  for (auto& request : expected.requests) {
    if (!request.answered) continue;
    if (next == parsed.size()) fail("a request of the batch got no response", line, *answer);
    match(request, parsed[next++], line, *answer);
  }
  if (next != parsed.size()) fail("a batch answered with more responses than asked", line, *answer);
}

}  // namespace cncd::fuzz
