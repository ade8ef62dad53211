// What the control protocol owes a request line, worked out from the line alone, and the check
// of the answer the dispatcher gave against it (rpc_fuzz.cpp). A breach prints the line and the
// answer and aborts, which libFuzzer reports as a crash.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace cncd::fuzz {

// One request of a line: a lone request, or an element of a batch.
struct Request {
  bool answered = true;  // false for a notification (an object without "id")
  nlohmann::json id;     // the id the answer must carry (null for a non-object)
  std::string method;    // "" when it names none
  bool control = false;  // names a method that needs the control group
  bool answer_error = false;
  int answer_code = 0;    // the error code it was answered with, once answered
  bool deferred = false;  // answered later through Completions (mdi.execute, program.abort)
};

struct Expectation {
  // The line as a whole is refused with one error whose id is null: not JSON, nested too
  // deeply, an empty batch or one too long.
  bool line_error = false;
  bool valid_json = false;
  bool batch = false;
  std::vector<Request> requests;
  nlohmann::json parsed;  // the line as nlohmann::json reads it (discarded when not JSON)
};

Expectation expect(const std::string& line);

// Checks `answer` (what handle_line returned) against `expected` and records each request's
// answer in it. `deferred_ids` are the ids the dispatcher filed as answered later during this
// line (Session::open_requests grew by them).
void check_answer(const std::string& line, const std::optional<std::string>& answer,
                  Expectation& expected, const std::vector<nlohmann::json>& deferred_ids);

// Checks an answer posted later (Completions): an error needs a message, and no answer may be
// an internal error.
void check_completion(int error_code, const std::string& message, const nlohmann::json& id);

[[noreturn]] void fail(const std::string& what, const std::string& line, const std::string& answer);

}  // namespace cncd::fuzz
