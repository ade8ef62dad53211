// What every connection of cncd-web shares: the configuration, the users, sessions, lease and
// program directory, the WebSockets open now (for lease.changed) and the time estimates.
// Everything here is used from the one I/O thread only; argon2 and cncd-check run on workers
// that post their results back.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ssl/context.hpp>
#include <boost/asio/thread_pool.hpp>
#include <nlohmann/json.hpp>

#include "cncd/config/machine_config.hpp"
#include "cncd/web/lease.hpp"
#include "cncd/web/program_dir.hpp"
#include "cncd/web/sessions.hpp"
#include "cncd/web/users.hpp"
#include "estimates.hpp"

namespace cncd::web {

// Who a request comes from, once authenticated by cookie or API key.
struct Identity {
  std::string user;
  Role role = Role::observer;
  // The login session (cookie); for an API key a session made for the key's WebSockets, so
  // that the lease has someone to belong to.
  Session session;
  bool by_key = false;
};

// A WebSocket as the rest of the server sees it.
class WsPeer {
 public:
  virtual ~WsPeer() = default;
  // Sends a notification frame (queued like any other).
  virtual void notify(const std::string& text) = 0;
  // Closes the WebSocket with `reason` (a session dropped: logout, user deleted).
  virtual void close_with(const std::string& reason) = 0;
  virtual const std::string& session_id() const = 0;
};

struct ServerLimits {
  std::size_t header_bytes = 16 * 1024;
  std::size_t body_bytes = 1024 * 1024;                 // any request but an upload
  std::size_t ws_message_bytes = 1024 * 1024;           // one frame from a client
  std::size_t ws_queue_bytes = 64 * 1024 * 1024;        // queued to one slow client, then closed
  std::size_t upstream_line_bytes = 256 * 1024 * 1024;  // one answer from cncd (a preview)
  int header_seconds = 10;          // a request's header must arrive within this (slowloris)
  int body_idle_seconds = 30;       // an upload or body that stalls this long is dropped
  std::size_t max_connections = 0;  // HTTP connections at once; 0 = 4 x MAX_CLIENTS + 16
};

struct App {
  // `machine_config.web` with its defaults filled in (PROGRAM_DIR, USERS_FILE); `check` is
  // cncd-check for the estimates ("" for none).
  App(boost::asio::io_context& io_context, config::MachineConfig machine_config,
      const std::filesystem::path& check);

  boost::asio::io_context& io;
  config::MachineConfig machine;
  config::WebConfig& web;
  std::string socket_path;        // cncd's control socket
  std::filesystem::path www_dir;  // the page's files
  std::optional<boost::asio::ssl::context> tls;
  ServerLimits limits;

  UsersFile users;
  std::string dummy_hash;  // checked against for unknown names: no timing tells names apart
  SessionStore sessions;
  LoginLimiter limiter;
  ControlLease lease;
  ProgramDir programs;
  Estimates estimates;
  boost::asio::thread_pool workers{1};  // argon2 verification

  std::map<std::string, Session> key_sessions;  // by user: the session of API-key clients
  std::set<WsPeer*> peers;
  std::size_t connections = 0;  // HTTP and WebSocket connections open
  // The program cncd has open (absolute path) as last seen in a status answer; "" = none.
  std::filesystem::path open_program;
  bool program_running = false;
  // Who has manual motion in cncd now (status "manual_holder"), null when nothing jogs.
  nlohmann::json manual_holder;

  // Reloads the users file when the command line changed it; "" or why it could not.
  std::string refresh_users();
  // The identity behind a cookie header value or an "Authorization" header value.
  std::optional<Identity> identify(std::string_view cookie, std::string_view authorization);
  // The running program for the file checks ("" when none runs).
  std::filesystem::path running() const {
    return program_running ? open_program : std::filesystem::path();
  }
  // lease.changed to every WebSocket.
  void broadcast(const std::string& text);
  // Closes the WebSockets of the dropped sessions and releases their lease.
  void sessions_dropped(const std::vector<std::string>& ids);
  nlohmann::json lease_json() const;
  // An Origin header may change things: absent, the page's own ("http(s)://" + Host), or in
  // [WEB] ALLOWED_ORIGINS.
  bool origin_allowed(std::string_view origin, std::string_view host, bool secure) const;
};

// PROGRAM_DIR (the first program directory) and USERS_FILE (web-users in the state
// directory) when the INI leaves them out.
config::MachineConfig with_web_defaults(config::MachineConfig machine);

// The JSON of a lease holder, or null.
nlohmann::json lease_holder_json(const std::optional<LeaseHolder>& holder);

}  // namespace cncd::web
