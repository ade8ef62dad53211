// The control socket: a Unix stream socket speaking JSON-RPC 2.0, one JSON object per line,
// with status subscriptions pushed as "status.update" notifications.
// Single-threaded: every method runs on the thread that calls poll_once().
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "access.hpp"
#include "event_log.hpp"
#include "logging.hpp"
#include "rpc.hpp"
#include "status_cache.hpp"

namespace cncd::daemon {

// How many connections cncd keeps ([CNCD] MAX_CONNECTIONS, MAX_CONNECTIONS_PER_USER,
// CONTROL_RESERVE; docs/protocol.md).
struct ConnectionLimits {
  std::size_t total = 1000;
  std::size_t per_user = 128;  // root and cncd's own user have no cap of their own
  std::size_t control_reserve = 8;
};

class Server {
 public:
  using Clock = std::chrono::steady_clock;
  // Largest request line accepted; a longer one gets an error and the connection is closed.
  static constexpr std::size_t kMaxLineBytes = 1 << 20;
  // Unfinished request lines kept across all connections; past it the connections with the
  // longest ones are told so and closed.
  static constexpr std::size_t kInputBudgetBytes = 16 << 20;
  // Unsent output past which a client that does not read is disconnected.
  static constexpr std::size_t kMaxBacklogBytes = 4 << 20;
  // Deferred answers one connection may be owed; its further requests wait in its socket
  // (stops among them are still acted on) until one is answered.
  static constexpr std::size_t kMaxOwedAnswers = 16;
  // Large answers ready while the backlog is full, held for a client until it reads; past this
  // it is asking for more than it reads and is disconnected.
  static constexpr std::size_t kMaxHeldBytes = 32 << 20;
  static constexpr int kMinSubscribeIntervalMs = 10;
  // Complete lines read ahead of serving from one connection; the rest waits in its socket.
  static constexpr std::size_t kReadAheadBytes = 64 << 10;
  // Work a connection gets per turn, and all connections together, in bytes of requests read
  // and answers written: a turn stays short whatever clients send, and the stops read at its
  // start are never far off.
  static constexpr std::size_t kClientBytesPerTurn = 32 << 10;
  static constexpr std::size_t kTurnBytes = 128 << 10;
  // Parsing a request line costs this many bytes of the budget per byte of the line.
  static constexpr std::size_t kParseCost = 4;
  // Status updates sent per turn; due ones past it go out in the next turns.
  static constexpr std::size_t kUpdatesPerTurn = 32;
  // How long a closing connection may take to read what is still owed to it.
  static constexpr std::chrono::seconds kCloseGrace{5};
  // Descriptors kept below RLIMIT_NOFILE for everything but connections.
  static constexpr std::size_t kDescriptorHeadroom = 32;
  // How long the listening socket rests after accept() failed for want of descriptors.
  static constexpr std::chrono::milliseconds kAcceptBackoff{100};

  // `status` is the status object for status.get and subscriptions, made fresh each turn;
  // every entry added to `events` is pushed to every client as an "event" notification.
  // Answers posted to `completions` go to the clients whose requests are waiting for them.
  Server(const RpcDispatcher& dispatcher, AccessPolicy policy, StatusCache& status,
         const EventLog& events, Completions& completions, ConnectionLimits limits = {});
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
  // The connection limits in force: the configured ones, lowered to fit RLIMIT_NOFILE.
  const ConnectionLimits& limits() const { return limits_; }

 private:
  struct Client {
    int fd = -1;
    uid_t uid = 0;
    bool capped = true;  // counts against the per-user cap
    Session session;
    std::string in;
    std::size_t complete = 0;                 // bytes of `in` up to and including its last newline
    std::size_t stop_scanned = 0;             // bytes of `in` already searched for a stop
    std::optional<RpcDispatcher::Line> line;  // a line served in part
    std::string out;
    // Bytes of `out` the client asked for in one large answer (program.preview): the largest
    // such answer may wait beyond kMaxBacklogBytes until the client has read it.
    std::size_t asked_bytes = 0;
    // Large answers (request id, result) that became ready while `out` was over the backlog:
    // sent as it drains, so that a client that reads is not cut off for having asked several
    // at once, and their results shared with the previews kept rather than copied.
    std::deque<std::pair<nlohmann::json, std::shared_ptr<const std::string>>> held;
    std::size_t held_bytes = 0;
    // Reads no more; closed once `out` is flushed and no deferred answer is owed, or when
    // `out` is still unsent at `close_by`.
    bool closing = false;
    Clock::time_point close_by;
    // Status as this client last saw it: the whole of it, or the fields it subscribed to.
    std::shared_ptr<const nlohmann::json> last_whole;
    nlohmann::json last_view;
    Clock::time_point next_update;  // when the next status update is due
    Clock::time_point last_update;  // when the last one was sent
    std::uint64_t update_seq = 0;
    std::uint64_t event_seq = 0;  // last event pushed to this client
  };
  // server_admit.cpp: who gets a connection, and how much unfinished input is kept.
  void accept_clients();
  void admit(int fd);
  void take_with_spare();
  std::string refusal(Access access, uid_t uid, bool capped) const;
  void bound_input();
  // The peer is gone or misbehaves: nothing more is sent to it.
  static void drop(Client& client);
  static void stop_reading(Client& client);
  static bool wants_input(const Client& client);
  bool has_work(const Client& client) const;
  // Whether `client` may be served no further requests now: its output is backed up or it is
  // owed kMaxOwedAnswers deferred answers.
  static bool backed_up(const Client& client);
  // Disconnects a client that does not read: logs `what`, tells it `reason` if it reads on.
  void cut_off(Client& client, const std::string& what, const std::string& reason);
  // Appends the answer with `id` and serialized `result`, or holds it while the backlog is full.
  void answer_raw(Client& client, const nlohmann::json& id,
                  std::shared_ptr<const std::string> result);
  void read_client(Client& client);
  static std::size_t stop_through(Client& client);
  void serve_stops();
  void serve_turn();
  // Serves the line in progress and the next ones while `budget` lasts, and those before
  // `through` in `in` whatever the budget.
  void serve_client(Client& client, std::size_t& budget, std::size_t through);
  void write_client(Client& client);
  // server_push.cpp: what the server sends unasked.
  void push_updates(Clock::time_point now);
  void push_events();
  void deliver_completions();
  int next_update_in_ms(Clock::time_point now) const;

  const RpcDispatcher& dispatcher_;
  AccessPolicy policy_;
  StatusCache& status_;
  const EventLog& events_;
  Completions& completions_;
  ConnectionLimits limits_;
  int listen_fd_ = -1;
  int spare_fd_ = -1;  // given up to take a connection when descriptors run out
  Clock::time_point listen_rests_until_;
  std::string path_;  // empty when the socket was handed over
  std::vector<Client> clients_;
  std::size_t next_client_ = 0;         // where the next turn's round starts
  std::size_t next_update_client_ = 0;  // where the next turn's status updates start
  bool requests_handled_ = false;       // a request was served in this poll_once
  std::uint64_t last_connection_ = 0;   // the id of the last connection admitted
  LogLimiter accept_log_;
  LogLimiter refusal_log_;
  LogLimiter client_log_;
};

// {"a":1,"b":{"c":2}} vs {"a":1,"b":{"c":3}} gives {"b":{"c":3}}: a JSON merge patch (RFC 7386)
// taking `before` to `after`, for objects whose keys do not disappear.
nlohmann::json merge_diff(const nlohmann::json& before, const nlohmann::json& after);

}  // namespace cncd::daemon
