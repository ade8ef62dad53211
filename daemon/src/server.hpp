// The control socket: a Unix stream socket speaking JSON-RPC 2.0, one JSON object per line,
// with status subscriptions pushed as "status.update" notifications.
// Single-threaded: every method runs on the thread that calls poll_once().
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "access.hpp"
#include "event_log.hpp"
#include "rpc.hpp"

namespace cncd::daemon {

class Server {
 public:
  using Clock = std::chrono::steady_clock;
  // Largest request line accepted; a longer one gets an error and the connection is closed.
  static constexpr std::size_t kMaxLineBytes = 1 << 20;
  // Unsent output past which a client that does not read is disconnected.
  static constexpr std::size_t kMaxBacklogBytes = 4 << 20;
  static constexpr int kMinSubscribeIntervalMs = 10;
  // Requests served from one client per loop turn (a batch's requests count one by one; the
  // line that reaches the count is served whole), so that a burst from one client does not
  // hold up the others.
  static constexpr std::size_t kRequestsPerTurn = 32;
  // How long a closing connection may take to read what is still owed to it.
  static constexpr std::chrono::seconds kCloseGrace{5};

  // `status` produces the full status object for subscriptions (called at most once a loop);
  // every entry added to `events` is pushed to every client as an "event" notification.
  // Answers posted to `completions` go to the clients whose requests are waiting for them.
  Server(const RpcDispatcher& dispatcher, AccessPolicy policy,
         std::function<nlohmann::json()> status, const EventLog& events, Completions& completions);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and listens on `path`; a stale socket file left by a dead daemon is replaced, a live
  // one is an error. Returns "" or an error message.
  std::string listen(const std::string& path);
  // Serves an already listening socket handed over by systemd.
  void adopt(int listen_fd);
  // Waits up to timeout_ms for socket activity (and `extra_fd` readability when >= 0), serves
  // it and pushes due status updates.
  void poll_once(int timeout_ms, int extra_fd = -1);
  // Sends the answers posted since the last poll (at shutdown: the opens it cancelled) as far
  // as the sockets take them without waiting.
  void flush_answers() { deliver_completions(); }
  // Closes every connection and removes the socket file (when this server created it).
  void close();
  std::size_t client_count() const { return clients_.size(); }

 private:
  struct Client {
    int fd = -1;
    Session session;
    std::string in;
    std::string out;
    // Reads no more; closed once `out` is flushed and no deferred answer is owed, or when
    // `out` is still unsent at `close_by`.
    bool closing = false;
    Clock::time_point close_by;
    nlohmann::json last_sent;       // status as this client last saw it
    Clock::time_point next_update;  // when the next status update is due
    Clock::time_point last_update;  // when the last one was sent
    std::uint64_t update_seq = 0;
    std::uint64_t event_seq = 0;  // last event pushed to this client
  };
  void accept_clients();
  // The peer is gone or misbehaves: nothing more is sent to it.
  static void drop(Client& client);
  static void stop_reading(Client& client);
  static bool has_pending_line(const Client& client);
  void read_client(Client& client);
  void serve_lines(Client& client);
  void write_client(Client& client);
  void push_updates(Clock::time_point now);
  void push_events();
  void deliver_completions();
  int next_update_in_ms(Clock::time_point now) const;

  const RpcDispatcher& dispatcher_;
  AccessPolicy policy_;
  std::function<nlohmann::json()> status_;
  const EventLog& events_;
  Completions& completions_;
  int listen_fd_ = -1;
  std::string path_;  // empty when the socket was handed over
  std::vector<Client> clients_;
  bool requests_handled_ = false;  // a request was served in this poll_once
};

// {"a":1,"b":{"c":2}} vs {"a":1,"b":{"c":3}} gives {"b":{"c":3}}: a JSON merge patch (RFC 7386)
// taking `before` to `after`, for objects whose keys do not disappear.
nlohmann::json merge_diff(const nlohmann::json& before, const nlohmann::json& after);

}  // namespace cncd::daemon
