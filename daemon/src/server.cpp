#include "server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string_view>

#include <spdlog/spdlog.h>

namespace cncd::daemon {
namespace {

std::string errno_text() {
  return std::strerror(errno);
}

bool fill_address(const std::string& path, sockaddr_un& addr) {
  std::memset(&addr, 0, sizeof addr);
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path) return false;
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  return true;
}

// The methods that stop the machine, as a request names them (with the quotes: a string
// elsewhere in a line that merely holds these words only makes the line be served early).
constexpr std::array<std::string_view, 5> kStops = {"\"machine.estop\"", "\"machine.off\"",
                                                    "\"jog.stop\"", "\"program.pause\"",
                                                    "\"program.abort\""};
constexpr std::size_t kLongestStop = 15;

// The configured limits, lowered to fit the descriptors this process may open.
ConnectionLimits fit_limits(ConnectionLimits limits) {
  rlimit files{};
  if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur != RLIM_INFINITY) {
    const auto room = files.rlim_cur > Server::kDescriptorHeadroom + 2
                          ? static_cast<std::size_t>(files.rlim_cur) - Server::kDescriptorHeadroom
                          : std::size_t{2};
    if (limits.total > room) {
      spdlog::warn("MAX_CONNECTIONS {} lowered to {} to fit RLIMIT_NOFILE {}", limits.total, room,
                   files.rlim_cur);
      limits.total = room;
    }
  }
  limits.control_reserve = std::min(limits.control_reserve, limits.total - 1);
  return limits;
}

}  // namespace

Server::Server(const RpcDispatcher& dispatcher, AccessPolicy policy, StatusCache& status,
               const EventLog& events, Completions& completions, ConnectionLimits limits)
    : dispatcher_(dispatcher),
      policy_(policy),
      status_(status),
      events_(events),
      completions_(completions),
      limits_(fit_limits(limits)),
      spare_fd_(::open("/dev/null", O_RDONLY | O_CLOEXEC)),
      accept_log_(std::chrono::minutes(1), 5),
      refusal_log_(std::chrono::minutes(1), 10),
      client_log_(std::chrono::minutes(1), 10) {}

Server::~Server() {
  close();
  if (spare_fd_ >= 0) ::close(spare_fd_);
}

void Server::adopt(int listen_fd) {
  const int flags = fcntl(listen_fd, F_GETFL);
  fcntl(listen_fd, F_SETFL, flags | O_NONBLOCK);
  listen_fd_ = listen_fd;
  path_.clear();
}

std::string Server::listen(const std::string& path) {
  sockaddr_un addr{};
  if (!fill_address(path, addr)) {
    return "socket path '" + path + "' is empty or longer than " +
           std::to_string(sizeof addr.sun_path - 1) + " bytes";
  }
  std::error_code ec;
  const auto dir = std::filesystem::path(path).parent_path();
  if (!dir.empty() && !std::filesystem::exists(dir, ec)) {
    std::filesystem::create_directories(dir, ec);
    if (ec) return "cannot create socket directory '" + dir.string() + "': " + ec.message();
  }
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return "socket(): " + errno_text();
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0) {
    if (!S_ISSOCK(st.st_mode)) {
      ::close(fd);
      return "'" + path + "' exists and is not a socket";
    }
    const int probe = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const bool live =
        probe >= 0 && ::connect(probe, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) == 0;
    if (probe >= 0) ::close(probe);
    if (live) {
      ::close(fd);
      return "another cncd is already serving '" + path + "'";
    }
    ::unlink(path.c_str());
  }
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string message = "bind('" + path + "'): " + errno_text();
    ::close(fd);
    return message;
  }
  // Every local user may connect; what a connection may do is decided per request.
  ::chmod(path.c_str(), 0666);
  if (::listen(fd, 64) != 0) {
    const std::string message = "listen(): " + errno_text();
    ::close(fd);
    ::unlink(path.c_str());
    return message;
  }
  listen_fd_ = fd;
  path_ = path;
  return "";
}

void Server::close() {
  for (auto& client : clients_)
    ::close(client.fd);
  clients_.clear();
  if (listen_fd_ >= 0) {
    ::close(listen_fd_);
    listen_fd_ = -1;
    if (!path_.empty()) ::unlink(path_.c_str());
  }
}

void Server::drop(Client& client) {
  client.in.clear();
  client.complete = 0;
  client.stop_scanned = 0;
  client.line.reset();
  client.out.clear();
  client.session.open_requests.clear();
  client.held.clear();
  client.held_bytes = 0;
  client.closing = true;
}

void Server::stop_reading(Client& client) {
  client.closing = true;
  client.close_by = Clock::now() + kCloseGrace;
}

// Lines are read ahead up to kReadAheadBytes, so that the stops among them are seen however
// much the connection has queued; an unfinished line is read on to its end.
bool Server::wants_input(const Client& client) {
  return !client.closing && (client.complete == 0 || client.in.size() < kReadAheadBytes);
}

bool Server::backed_up(const Client& client) {
  return client.out.size() > kMaxBacklogBytes || !client.held.empty() ||
         client.session.open_requests.size() >= kMaxOwedAnswers;
}

bool Server::has_work(const Client& client) const {
  return (client.line || client.complete > 0) && !backed_up(client);
}

void Server::read_client(Client& client) {
  char buffer[65536];
  while (wants_input(client)) {
    const ssize_t n = ::read(client.fd, buffer, sizeof buffer);
    if (n == 0) {
      // A peer that only shut down its sending side (as socat and nc -N do) still gets the
      // answers to what it sent; one that has gone makes the next send fail.
      stop_reading(client);
      return;
    }
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) drop(client);
      return;
    }
    const auto size = static_cast<std::size_t>(n);
    if (const void* last = memrchr(buffer, '\n', size)) {
      client.complete =
          client.in.size() + static_cast<std::size_t>(static_cast<const char*>(last) - buffer + 1);
    }
    client.in.append(buffer, size);
    if (client.in.size() - client.complete > kMaxLineBytes) {
      nlohmann::json error = {
          {"jsonrpc", "2.0"},
          {"id", nullptr},
          {"error", RpcDispatcher::error_object(kRequestTooLarge, "request longer than 1 MiB")}};
      client.out += error.dump() + "\n";
      client.in.resize(client.complete);
      stop_reading(client);
      return;
    }
  }
}

// The end (past its newline) of the last complete line of `in` that names a stop; 0 when none.
std::size_t Server::stop_through(Client& client) {
  if (client.complete == 0) return 0;
  const std::size_t from =
      client.stop_scanned > kLongestStop ? client.stop_scanned - kLongestStop : 0;
  const std::string_view window = std::string_view(client.in).substr(from, client.complete - from);
  std::size_t through = 0;
  for (const auto stop : kStops) {
    const std::size_t at = window.rfind(stop);
    if (at != std::string_view::npos)
      through = std::max(through, client.in.find('\n', from + at) + 1);
  }
  client.stop_scanned = client.complete;
  return through;
}

// A stop from a control connection is served first, with what that connection sent before it
// (its own requests keep their order), ahead of every other connection's work. A read-only
// connection's lines cannot stop anything and get no precedence.
void Server::serve_stops() {
  for (auto& client : clients_) {
    if (client.session.access != Access::control) continue;
    if (const std::size_t through = stop_through(client); through > 0) {
      std::size_t budget = 0;
      serve_client(client, budget, through);
    }
  }
}

// The rest of the turn: connections in turn, from where the last turn's round ended, each up
// to kClientBytesPerTurn until kTurnBytes are used.
void Server::serve_turn() {
  const std::size_t count = clients_.size();
  std::size_t turn_left = kTurnBytes;
  std::size_t k = 0;
  for (; k < count && turn_left > 0; ++k) {
    Client& client = clients_[(next_client_ + k) % count];
    if (!has_work(client)) continue;
    const std::size_t given = std::min(turn_left, kClientBytesPerTurn);
    std::size_t budget = given;
    serve_client(client, budget, 0);
    turn_left -= given - budget;
  }
  next_client_ = count == 0 ? 0 : (next_client_ + k) % count;
}

void Server::serve_client(Client& client, std::size_t& budget, std::size_t through) {
  std::size_t start = 0;
  for (;;) {
    const bool priority = start < through;
    if (!priority && (budget == 0 || backed_up(client))) break;
    if (!client.line) {
      if (start >= client.complete) break;
      const std::size_t newline = client.in.find('\n', start);
      std::string text = client.in.substr(start, newline - start);
      start = newline + 1;
      if (!text.empty() && text.back() == '\r') text.pop_back();
      if (text.find_first_not_of(" \t") == std::string::npos) continue;
      budget -= std::min(budget, kParseCost * text.size());
      client.line = dispatcher_.begin_line(text);
    }
    requests_handled_ = true;
    std::size_t unlimited = SIZE_MAX;
    const bool done =
        dispatcher_.serve(*client.line, client.session, priority ? unlimited : budget);
    if (!done) break;
    if (auto response = RpcDispatcher::answer(*client.line)) {
      client.out += *response;
      client.out += '\n';
    }
    client.line.reset();
  }
  client.in.erase(0, start);
  client.complete -= start;
  client.stop_scanned -= std::min(client.stop_scanned, start);
  if (client.in.empty() && client.in.capacity() > kReadAheadBytes) std::string().swap(client.in);
}

void Server::write_client(Client& client) {
  for (;;) {
    while (!client.out.empty()) {
      const ssize_t n = ::send(client.fd, client.out.data(), client.out.size(), MSG_NOSIGNAL);
      if (n < 0) {
        if (errno == EINTR) continue;
        if (errno != EAGAIN && errno != EWOULDBLOCK) drop(client);
        break;
      }
      client.out.erase(0, static_cast<std::size_t>(n));
    }
    // Held answers follow as the backlog drains; each one appended leaves it full or none held.
    if (client.held.empty() || client.out.size() > kMaxBacklogBytes) break;
    while (!client.held.empty() && client.out.size() <= kMaxBacklogBytes) {
      auto [id, result] = std::move(client.held.front());
      client.held.pop_front();
      client.held_bytes -= result->size();
      answer_raw(client, id, std::move(result));
    }
  }
  client.asked_bytes = std::min(client.asked_bytes, client.out.size());
  if (client.out.size() > kMaxBacklogBytes + client.asked_bytes) {
    cut_off(client, std::to_string(client.out.size()) + " bytes unsent",
            "client does not read its messages: backlog over 4 MiB");
  }
}

void Server::cut_off(Client& client, const std::string& what, const std::string& reason) {
  client_log_.log(spdlog::level::warn, "control client not reading: " + what + ", disconnecting");
  // What it never read is dropped; the reason is sent once it reads what the socket holds
  // (within kCloseGrace). The newline ends a line the last send may have cut.
  const nlohmann::json notice = {
      {"jsonrpc", "2.0"}, {"method", "connection.closing"}, {"params", {{"reason", reason}}}};
  drop(client);
  client.out = "\n" + notice.dump() + "\n";
  stop_reading(client);
}

void Server::poll_once(int timeout_ms, int extra_fd) {
  // Answers posted since the last call (program.abort at rest, mdi.execute done) go out now,
  // not after the wait.
  deliver_completions();
  auto now = Clock::now();
  const int update_in = next_update_in_ms(now);
  if (update_in >= 0 && update_in < timeout_ms) timeout_ms = update_in;
  const bool listening = now >= listen_rests_until_;
  if (!listening) {
    const auto rest = std::chrono::ceil<std::chrono::milliseconds>(listen_rests_until_ - now);
    timeout_ms = std::min<int>(timeout_ms, static_cast<int>(rest.count()));
  }
  std::vector<pollfd> fds;
  fds.reserve(clients_.size() + 2);
  fds.push_back({listening ? listen_fd_ : -1, POLLIN, 0});
  fds.push_back({extra_fd, POLLIN, 0});
  for (const auto& client : clients_) {
    if (has_work(client)) timeout_ms = 0;
    short events = wants_input(client) ? POLLIN : 0;
    if (!client.out.empty()) events |= POLLOUT;
    // Left out while it waits for a deferred answer: a hung-up peer would wake poll at once.
    fds.push_back({events != 0 ? client.fd : -1, events, 0});
  }
  const int ready = ::poll(fds.data(), fds.size(), timeout_ms);
  const std::size_t known = clients_.size();
  // Every connection's input is read before any is served, so that the stops among it are
  // served first.
  for (std::size_t i = 0; i < known && ready > 0; ++i) {
    if ((fds[i + 2].events & POLLIN) && (fds[i + 2].revents & (POLLIN | POLLHUP | POLLERR)))
      read_client(clients_[i]);
  }
  bound_input();
  status_.invalidate();
  serve_stops();
  serve_turn();
  for (auto& client : clients_) {
    if (!client.out.empty()) write_client(client);
  }
  if (ready > 0 && (fds[0].revents & POLLIN)) accept_clients();
  deliver_completions();
  push_events();
  push_updates(Clock::now());
  requests_handled_ = false;
  for (const auto& client : clients_) {
    if (client.closing) dispatcher_.closed(client.session);
  }
  now = Clock::now();
  std::erase_if(clients_, [now](const Client& client) {
    const bool done = client.out.empty() && client.held.empty() &&
                      client.session.open_requests.empty() && client.complete == 0 && !client.line;
    if (client.closing && (done || (!client.out.empty() && now >= client.close_by))) {
      ::close(client.fd);
      return true;
    }
    return false;
  });
}

}  // namespace cncd::daemon
