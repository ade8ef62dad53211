// A small HTTP and WebSocket client (Boost.Beast, blocking) for the tests of cncd-web.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace cncd::test {

using Headers = std::vector<std::pair<std::string, std::string>>;

struct HttpReply {
  int status = 0;  // 0: no answer (connection refused, reset or timed out)
  std::string body;
  std::map<std::string, std::string> headers;  // names in lower case
  std::string header(const std::string& name) const {
    const auto found = headers.find(name);
    return found == headers.end() ? "" : found->second;
  }
  nlohmann::json json() const { return nlohmann::json::parse(body, nullptr, false); }
};

// One request on a new connection to 127.0.0.1:port; `target` is sent as given.
HttpReply http_request(int port, const std::string& method, const std::string& target,
                       const std::string& body = "", const Headers& headers = {});

// Sends `bytes` on a new connection and returns what comes back until the server closes it or
// `timeout_ms` passes; `closed` tells which.
struct RawReply {
  std::string text;
  bool closed = false;
};
RawReply raw_exchange(int port, const std::string& bytes, int timeout_ms);

class WsClient {
 public:
  WsClient();
  ~WsClient();
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;

  // Opens /ws with these headers (Cookie, Origin, Authorization); the handshake's HTTP
  // status: 101 when open.
  int open(int port, const Headers& headers);
  void send(const nlohmann::json& message);
  void send_text(const std::string& text);
  // The next frame, or nullopt when none came within `timeout_ms` or the connection ended.
  std::optional<nlohmann::json> read(int timeout_ms = 30000);
  // Sends a request with a fresh id and returns its answer; notifications read meanwhile go to
  // notifications(). Null when no answer came.
  nlohmann::json call(const std::string& method, const nlohmann::json& params = nullptr);
  // The answer to a request sent with send() whose id is `id`.
  nlohmann::json answer_to(int id);
  std::vector<nlohmann::json>& notifications() { return notifications_; }
  // Ends the TCP connection without a close frame (a browser killed).
  void drop();
  // A proper close.
  void close();
  bool is_open() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<nlohmann::json> notifications_;
  int next_id_ = 1000;
};

}  // namespace cncd::test
