// A blocking JSON-RPC client for the control socket (cncctl, tests).
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace cncd::daemon {

class Client {
 public:
  Client() = default;
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  // Returns "" or an error message.
  std::string connect(const std::string& socket_path);
  // Sends one request and waits up to timeout_ms for its response object (the whole
  // {"jsonrpc", "id", "result"|"error"} object). Throws std::runtime_error on I/O failure or
  // timeout.
  nlohmann::json call(const std::string& method, const nlohmann::json& params = nullptr,
                      int timeout_ms = 10000);
  // Sends raw bytes (tests of malformed input).
  void send_raw(const std::string& bytes);
  // Reads one line, waiting up to timeout_ms. Throws std::runtime_error on failure.
  std::string read_line(int timeout_ms = 10000);
  // The same, but returns nullopt when no line came within timeout_ms (or a signal
  // interrupted the wait).
  std::optional<std::string> try_read_line(int timeout_ms);

 private:
  int fd_ = -1;
  long next_id_ = 1;
  std::string buffer_;
};

}  // namespace cncd::daemon
