#include "server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include <spdlog/spdlog.h>

#include "status_json.hpp"

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

}  // namespace

Server::Server(const RpcDispatcher& dispatcher, AccessPolicy policy,
               std::function<nlohmann::json()> status, const EventLog& events,
               Completions& completions)
    : dispatcher_(dispatcher),
      policy_(policy),
      status_(std::move(status)),
      events_(events),
      completions_(completions) {}

Server::~Server() {
  close();
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

void Server::accept_clients() {
  for (;;) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        spdlog::warn("accept on control socket failed: {}", errno_text());
      }
      return;
    }
    std::string who;
    const Access access = peer_access(fd, policy_, who);
    if (access == Access::none) {
      // Refused with a reason; the socket is non-blocking and the reply small, so a single
      // send either fits or the peer was not listening anyway.
      const nlohmann::json refusal = {
          {"jsonrpc", "2.0"},
          {"id", nullptr},
          {"error",
           RpcDispatcher::error_object(
               kPermissionDenied, "permission denied: " + who +
                                      " is neither root nor in cncd's read or control group")}};
      const std::string line = refusal.dump() + "\n";
      [[maybe_unused]] const ssize_t n = ::send(fd, line.data(), line.size(), MSG_NOSIGNAL);
      spdlog::info("control connection refused: {}", who);
      ::close(fd);
      continue;
    }
    Client client;
    client.fd = fd;
    client.session.access = access;
    client.event_seq = events_.last_seq();
    clients_.push_back(std::move(client));
  }
}

void Server::drop(Client& client) {
  client.in.clear();
  client.out.clear();
  client.session.open_requests.clear();
  client.closing = true;
}

void Server::stop_reading(Client& client) {
  client.closing = true;
  client.close_by = Clock::now() + kCloseGrace;
}

bool Server::has_pending_line(const Client& client) {
  return client.in.find('\n') != std::string::npos;
}

// Reads until a complete line is in: serve_lines() serves lines a few at a time, and what the
// client sends meanwhile stays in the socket.
void Server::read_client(Client& client) {
  char buffer[65536];
  bool line_complete = has_pending_line(client);
  while (!line_complete) {
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
    client.in.append(buffer, static_cast<std::size_t>(n));
    line_complete = std::memchr(buffer, '\n', static_cast<std::size_t>(n)) != nullptr;
    if (!line_complete && client.in.size() > kMaxLineBytes) {
      nlohmann::json error = {
          {"jsonrpc", "2.0"},
          {"id", nullptr},
          {"error", RpcDispatcher::error_object(kRequestTooLarge, "request longer than 1 MiB")}};
      client.out += error.dump() + "\n";
      client.in.clear();
      stop_reading(client);
      return;
    }
  }
}

void Server::serve_lines(Client& client) {
  std::size_t start = 0;
  // A batch counts as the requests it holds, so that batches get a client no more work done
  // in a turn than single requests do.
  std::size_t served = 0;
  while (served < kRequestsPerTurn && client.out.size() <= kMaxBacklogBytes) {
    const std::size_t newline = client.in.find('\n', start);
    if (newline == std::string::npos) break;
    std::string line = client.in.substr(start, newline - start);
    start = newline + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) {
      ++served;
      continue;
    }
    requests_handled_ = true;
    std::size_t requests = 1;
    auto response = dispatcher_.handle_line(line, client.session, &requests);
    served += requests;
    if (response) {
      client.out += *response;
      client.out += '\n';
    }
  }
  client.in.erase(0, start);
}

void Server::write_client(Client& client) {
  while (!client.out.empty()) {
    const ssize_t n = ::send(client.fd, client.out.data(), client.out.size(), MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) drop(client);
      break;
    }
    client.out.erase(0, static_cast<std::size_t>(n));
  }
  if (client.out.size() > kMaxBacklogBytes) {
    spdlog::warn("control client not reading: {} bytes unsent, disconnecting", client.out.size());
    // What it never read is dropped; the reason is sent once it reads what the socket holds
    // (within kCloseGrace). The newline ends a line the last send may have cut.
    const nlohmann::json notice = {
        {"jsonrpc", "2.0"},
        {"method", "connection.closing"},
        {"params", {{"reason", "client does not read its messages: backlog over 4 MiB"}}}};
    drop(client);
    client.out = "\n" + notice.dump() + "\n";
    stop_reading(client);
  }
}

nlohmann::json merge_diff(const nlohmann::json& before, const nlohmann::json& after) {
  if (!before.is_object() || !after.is_object()) return after;
  nlohmann::json patch = nlohmann::json::object();
  for (const auto& [key, value] : after.items()) {
    const auto old = before.find(key);
    if (old == before.end()) {
      patch[key] = value;
    } else if (*old != value) {
      patch[key] = value.is_object() && old->is_object() ? merge_diff(*old, value) : value;
    }
  }
  return patch;
}

int Server::next_update_in_ms(Clock::time_point now) const {
  int wait_ms = -1;
  for (const auto& client : clients_) {
    if (client.session.subscribe_interval_ms <= 0 || client.closing) continue;
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(client.next_update - now).count();
    const int ms = left < 0 ? 0 : static_cast<int>(left);
    wait_ms = wait_ms < 0 ? ms : std::min(wait_ms, ms);
  }
  return wait_ms;
}

void Server::push_updates(Clock::time_point now) {
  nlohmann::json status;  // produced once, only when some client is due
  for (auto& client : clients_) {
    const int interval = client.session.subscribe_interval_ms;
    if (interval <= 0) {
      client.last_sent = nullptr;
      continue;
    }
    // Besides the periodic check, a request that may have changed the state is followed at
    // once by an update to every client whose interval has passed since its last one.
    const auto period = std::chrono::milliseconds(interval);
    const bool due =
        now >= client.next_update || (requests_handled_ && now - client.last_update >= period);
    if (client.closing || !due) continue;
    client.next_update = now + period;
    // A client still holding unsent output gets the changes coalesced into a later update.
    if (!client.out.empty()) continue;
    if (status.is_null()) status = status_();
    nlohmann::json view;
    if (client.session.fields.empty()) {
      view = status;
    } else {
      view = nlohmann::json::object();
      for (const auto& field : client.session.fields) {
        if (const auto it = status.find(field); it != status.end()) view[field] = *it;
      }
    }
    nlohmann::json changed = client.last_sent.is_null() ? view : merge_diff(client.last_sent, view);
    if (changed.empty()) continue;
    const auto wall = std::chrono::system_clock::now().time_since_epoch();
    const nlohmann::json update = {{"jsonrpc", "2.0"},
                                   {"method", "status.update"},
                                   {"params",
                                    {{"seq", ++client.update_seq},
                                     {"time", std::chrono::duration<double>(wall).count()},
                                     {"full", client.last_sent.is_null()},
                                     {"changed", std::move(changed)}}}};
    client.last_sent = std::move(view);
    client.last_update = now;
    client.out += update.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    client.out += '\n';
    write_client(client);
  }
}

void Server::deliver_completions() {
  for (auto& done : completions_.take()) {
    for (auto& client : clients_) {
      auto& open = client.session.open_requests;
      const auto it = std::find_if(open.begin(), open.end(),
                                   [&](const auto& entry) { return entry.first == done.token; });
      if (it == open.end()) continue;
      nlohmann::json response = {{"jsonrpc", "2.0"}, {"id", it->second}};
      if (done.error_code == 0) {
        response["result"] = std::move(done.result);
      } else {
        response["error"] = RpcDispatcher::error_object(done.error_code, done.error_message);
      }
      open.erase(it);
      if (client.closing) client.close_by = Clock::now() + kCloseGrace;
      client.out += response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      client.out += '\n';
      write_client(client);
      break;
    }
  }
}

void Server::push_events() {
  const std::uint64_t last = events_.last_seq();
  for (auto& client : clients_) {
    if (client.closing || client.event_seq >= last) continue;
    for (const auto& event : events_.since(client.event_seq)) {
      const nlohmann::json note = {
          {"jsonrpc", "2.0"}, {"method", "event"}, {"params", event_json(event)}};
      client.out += note.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      client.out += '\n';
    }
    client.event_seq = last;
    write_client(client);
  }
}

void Server::poll_once(int timeout_ms, int extra_fd) {
  // Answers posted since the last call (program.abort at rest, mdi.execute done) go out now,
  // not after the wait.
  deliver_completions();
  const int update_in = next_update_in_ms(Clock::now());
  if (update_in >= 0 && update_in < timeout_ms) timeout_ms = update_in;
  std::vector<pollfd> fds;
  fds.reserve(clients_.size() + 2);
  fds.push_back({listen_fd_, POLLIN, 0});
  fds.push_back({extra_fd, POLLIN, 0});
  for (const auto& client : clients_) {
    // A client with requests still to serve is not read from meanwhile: back-pressure.
    const bool pending = has_pending_line(client);
    if (pending) timeout_ms = 0;
    short events = client.closing || pending ? 0 : POLLIN;
    if (!client.out.empty()) events |= POLLOUT;
    // Left out while it waits for a deferred answer: a hung-up peer would wake poll at once.
    fds.push_back({events != 0 ? client.fd : -1, events, 0});
  }
  const int ready = ::poll(fds.data(), fds.size(), timeout_ms);
  const std::size_t known = clients_.size();
  for (std::size_t i = 0; i < known; ++i) {
    const short revents = ready > 0 ? fds[i + 2].revents : 0;
    Client& client = clients_[i];
    if ((fds[i + 2].events & POLLIN) && (revents & (POLLIN | POLLHUP | POLLERR)))
      read_client(client);
    serve_lines(client);
    if (!client.out.empty()) write_client(client);
  }
  if (ready > 0 && (fds[0].revents & POLLIN)) accept_clients();
  deliver_completions();
  push_events();
  push_updates(Clock::now());
  requests_handled_ = false;
  const auto now = Clock::now();
  std::erase_if(clients_, [now](const Client& client) {
    const bool done =
        client.out.empty() && client.session.open_requests.empty() && !has_pending_line(client);
    if (client.closing && (done || (!client.out.empty() && now >= client.close_by))) {
      ::close(client.fd);
      return true;
    }
    return false;
  });
}

}  // namespace cncd::daemon
