// One WebSocket's JSON-RPC, apart from the transport: every request (each one of a batch) is
// checked against the session's role and the control lease, web-only methods are answered
// here, program names become paths inside PROGRAM_DIR, and what goes on to cncd carries the
// web user and address ("on_behalf_of") and, for jog.start, the heartbeat.
#pragma once

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "app.hpp"

namespace cncd::web {

// Error codes of cncd-web's own refusals (docs/protocol.md).
inline constexpr int kRoleRefused = 1020;
inline constexpr int kLeaseRefused = 1021;

class WsRpc {
 public:
  // A request whose slow part (argon2) runs on a worker: `work` there, then `finish` back on
  // the I/O thread with work's result; finish gives the answer frame ("" for a notification).
  struct Later {
    std::function<std::string()> work;
    std::function<std::string(std::string)> finish;
  };
  struct Output {
    std::vector<std::string> to_client;  // frames
    std::vector<std::string> to_daemon;  // lines
    std::optional<Later> later;
  };

  WsRpc(App& app, Identity who, std::string address);

  // A text frame from the client.
  Output on_client(std::string_view text);
  // The lines to send cncd before the connection closes: stops of the continuous jogs this
  // WebSocket started.
  std::vector<std::string> on_close();

  const Identity& identity() const { return who_; }

 private:
  // One request: its answer (null when forwarded or a notification) and, when forwarded, the
  // request as sent on.
  struct Handled {
    nlohmann::json answer;
    nlohmann::json forward;
  };
  Handled handle(nlohmann::json request);
  nlohmann::json web_method(const std::string& method, const nlohmann::json& params,
                            nlohmann::json& forward);

  // Set by web_method for a request answered later (users.add, users.passwd).
  std::optional<std::function<nlohmann::json(std::string)>> later_finish_;
  std::function<std::string()> later_work_;

  App& app_;
  Identity who_;
  std::string address_;
  std::set<std::string> jogging_;  // axes of continuous jogs started here
};

// A JSON-RPC error answer.
nlohmann::json rpc_error(const nlohmann::json& id, int code, const std::string& message);

// Thrown by web methods: answered as the error.
struct WebError {
  int code;
  std::string message;
};

}  // namespace cncd::web
