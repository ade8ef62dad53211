// One WebSocket's JSON-RPC, apart from the transport: every request (each one of a batch) is
// checked against the session's role and the control lease, web-only methods are answered
// here, program names become paths inside PROGRAM_DIR, and what goes on to cncd carries the
// web user and address ("on_behalf_of") and, for jog.start, the heartbeat.
#pragma once

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
  struct Output {
    std::vector<std::string> to_client;  // frames
    std::vector<std::string> to_daemon;  // lines
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
