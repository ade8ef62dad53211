// JSON-RPC 2.0 dispatch: one request (or batch) in, one response (or none) out.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rpc_params.hpp"
#include "task_outcome.hpp"

namespace cncd::daemon {

class EventLog;

// Stable error codes; docs/protocol.md lists them.
enum RpcCode : int {
  kParseError = -32700,
  kInvalidRequest = -32600,
  kMethodNotFound = -32601,
  kInvalidParams = -32602,
  kInternalError = -32603,
  kWrongState = 1001,    // not allowed in the machine's current state
  kNotHomed = 1002,      // motion needs homed joints
  kProgramError = 1003,  // the program could not be opened or was rejected
  kBusy = 1004,          // something else is running
  kPermissionDenied = 1005,
  kRequestTooLarge = 1006,
  kFileError = 1007,  // a file (tool table, parameter file) could not be written
  kFault = 1008,      // the machine did not do it: a drive, its feedback or the estop input
  kCancelled = 1009,  // cancelled before it finished (program.open: a newer open, an estop)
  kTooManyConnections = 1010,  // refused at connect: the connection limits are reached
  kAttributionRefused = 1011,  // "on_behalf_of" from a peer without control access
  kUnavailable = 1012,         // the job history's database cannot be opened or read
};

class RpcError : public std::runtime_error {
 public:
  RpcError(int code, const std::string& message) : std::runtime_error(message), code_(code) {}
  int code() const { return code_; }

 private:
  int code_;
};

// The code a refusal or failure of the task's is answered with.
int rpc_code(TaskErrorKind kind);

// Answers to requests that finish later (mdi.execute, program.abort): the handler takes a
// token with next_token() and sets it as the session's defer_token, the server keeps the
// request open, and the task posts the outcome with post(); the server sends it to the client
// that asked.
class Completions final : public TaskAnswers {
 public:
  struct Completion {
    std::uint64_t token = 0;
    nlohmann::json result;  // used when error_code == 0 and raw_result is not set
    std::shared_ptr<const std::string> raw_result;  // the result, serialized
    int error_code = 0;
    std::string error_message;
  };
  std::uint64_t next_token() { return ++last_token_; }
  // {"ok": true}, {"path": ...} or the error's code and message.
  void post(std::uint64_t token, TaskOutcome outcome) override;
  std::vector<Completion> take() { return std::exchange(done_, {}); }

 private:
  std::uint64_t last_token_ = 0;
  std::vector<Completion> done_;
};

// Per-connection state a method may read or change.
struct Session {
  Access access = Access::control;
  std::uint64_t connection = 0;     // which connection, for state kept per connection
  std::string peer;                 // "uid 1000 pid 4242", as the event log names the peer
  int subscribe_interval_ms = 0;    // 0: not subscribed to status updates
  std::vector<std::string> fields;  // top-level status fields wanted; empty = all
  // Set by a handler whose answer comes later; the dispatcher then files the request's id
  // under it in `open_requests` and sends nothing now.
  std::uint64_t defer_token = 0;
  std::vector<std::pair<std::uint64_t, nlohmann::json>> open_requests;  // token, request id
  bool in_batch = false;
};

class RpcDispatcher {
 public:
  // A handler gets the params as checked against its method's entry in the table (always an
  // object, holding only declared parameters of the declared types, optional ones left out
  // when absent or null) and the caller's session, and returns the result; it reports failure
  // by throwing RpcError, or TaskError (answered with rpc_code()). Called on the server's
  // thread.
  using Handler = std::function<nlohmann::json(const nlohmann::json& params, Session& session)>;
  using SimpleHandler = std::function<nlohmann::json(const nlohmann::json& params)>;
  // A range for a number parameter known only from the machine's configuration.
  struct Range {
    std::string_view param;
    double min;
    double max;
  };

  // Serves the methods of method_table().
  RpcDispatcher();
  explicit RpcDispatcher(std::vector<MethodSpec> table);

  // Throws std::logic_error for a method the table lacks, one added twice, or a range for a
  // parameter that is not a number: no method is served without its parameters declared.
  void add(const std::string& method, Handler handler, const std::vector<Range>& ranges = {});
  void add(const std::string& method, SimpleHandler handler, const std::vector<Range>& ranges = {});
  // Calls `hook` after each request to a method that needs control access has been handled.
  void after_command(std::function<void()> hook) { after_command_ = std::move(hook); }
  // Names the peer (or the person and address of "on_behalf_of") as `by` of the events a
  // request to a control method causes, and records each attributed request to a control
  // method (but those whose spec says not) as a "command" event.
  void record_to(EventLog* events) { events_ = events; }
  // Calls `hook` for a connection that closes (once its peer has hung up or been cut off, and
  // again each turn until it is gone): what it started to run only while it is there stops.
  void on_close(std::function<void(const Session&)> hook) { on_close_ = std::move(hook); }
  void closed(const Session& session) const {
    if (on_close_) on_close_(session);
  }
  // A method whose result the handler gives as serialized JSON: status.get hands out one
  // serialization of the status to every request of a turn instead of copying and printing it.
  using RawHandler = std::function<std::string(const nlohmann::json& params, Session& session)>;
  void add_raw(const std::string& method, RawHandler handler);
  // Throws std::logic_error naming the methods of the table that have no handler.
  void require_all_added() const;
  // Handles one line of input from a caller. Returns the serialized response without newline,
  // or nullopt when nothing is to be sent (notifications). `requests`, when given, receives
  // how many requests the line held (a batch's length, else 1).
  std::optional<std::string> handle_line(const std::string& line, Session& session,
                                         std::size_t* requests = nullptr) const;

  // The first key a request repeats in one of its objects; `id` when that request's own "id"
  // is among the repeated keys.
  struct RepeatedKey {
    std::string key;
    bool id = false;
  };
  // A line being served, perhaps over several turns of the server: a batch is answered a few
  // requests at a time, so that a batch of slow requests holds up no other connection.
  struct Line {
    nlohmann::json requests = nlohmann::json::array();  // a batch's requests, or the one
    bool batch = false;
    std::map<std::size_t, RepeatedKey> repeats;  // by request index
    std::size_t next = 0;                        // the next request to serve
    std::size_t answered = 0;
    std::string answers;               // the answers so far, separated by commas
    std::optional<std::string> whole;  // the answer to a line refused as a whole
  };
  // Parses a line; nothing of it is served yet.
  Line begin_line(const std::string& text) const;
  // What a request costs beyond its answer's bytes, in the same bytes: checking and
  // dispatching it, which a batch of requests with short answers must pay too.
  static constexpr std::size_t kRequestCost = 512;
  // Serves the line's next requests, at least one, until the line is done or the requests have
  // used up `budget` (lowered by their answers' bytes and kRequestCost each). True once the
  // line is done.
  bool serve(Line& line, Session& session, std::size_t& budget) const;
  // The answer to a line that is done, without newline; nullopt when nothing is to be sent.
  static std::optional<std::string> answer(Line& line);

  static nlohmann::json error_object(int code, const std::string& message);

 private:
  struct Entry {
    Handler handler;
    RawHandler raw;   // when set, serves the method instead of `handler`
    MethodSpec spec;  // with the ranges given to add()
  };
  std::optional<std::string> handle_one(const nlohmann::json& request, Session& session,
                                        const RepeatedKey* repeated) const;
  std::map<std::string, MethodSpec, std::less<>> table_;
  std::map<std::string, Entry, std::less<>> handlers_;
  std::function<void()> after_command_;
  EventLog* events_ = nullptr;
  std::function<void(const Session&)> on_close_;
};

}  // namespace cncd::daemon
