// Who gets a connection, and how much unfinished input the server keeps: no client can take
// every descriptor or the daemon's memory, and a control client can always connect.
#include <sys/socket.h>
#include <unistd.h>

#include <fcntl.h>
#include <algorithm>

#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>

#include "server.hpp"

namespace cncd::daemon {
namespace {

// Accepts per turn: a crowd of connects cannot make a turn long.
constexpr int kAcceptsPerTurn = 64;

// Tells a refused peer why and closes. The socket is non-blocking and the reply small, so a
// single send either fits or the peer was not listening anyway.
void refuse(int fd, int code, const std::string& message) {
  const nlohmann::json refusal = {
      {"jsonrpc", "2.0"}, {"id", nullptr}, {"error", RpcDispatcher::error_object(code, message)}};
  const std::string line = refusal.dump() + "\n";
  [[maybe_unused]] const ssize_t n = ::send(fd, line.data(), line.size(), MSG_NOSIGNAL);
  ::close(fd);
}

}  // namespace

void Server::accept_clients() {
  for (int i = 0; i < kAcceptsPerTurn; ++i) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd >= 0) {
      admit(fd);
      continue;
    }
    const int error = errno;
    if (error == EAGAIN || error == EWOULDBLOCK) return;
    if (error == EINTR || error == ECONNABORTED) continue;
    // Out of descriptors (or worse): the listening socket rests a while instead of waking
    // every turn to fail again, and the peer waiting first is told why.
    listen_rests_until_ = Clock::now() + kAcceptBackoff;
    accept_log_.log(spdlog::level::warn,
                    std::string("accept on control socket failed: ") + std::strerror(error));
    if (error == EMFILE || error == ENFILE) take_with_spare();
    return;
  }
}

void Server::take_with_spare() {
  if (spare_fd_ < 0) return;
  ::close(spare_fd_);
  const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
  if (fd >= 0) refuse(fd, kTooManyConnections, "cncd has no file descriptors left; try later");
  spare_fd_ = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
}

std::string Server::refusal(Access access, uid_t uid, bool capped) const {
  const std::size_t open = clients_.size();
  if (open >= limits_.total) {
    return "too many connections: cncd serves at most " + std::to_string(limits_.total);
  }
  if (access != Access::control && open + limits_.control_reserve >= limits_.total) {
    return "too many connections: the last " + std::to_string(limits_.control_reserve) + " of " +
           std::to_string(limits_.total) + " are kept for the control group";
  }
  if (capped) {
    const auto same = static_cast<std::size_t>(std::count_if(
        clients_.begin(), clients_.end(), [uid](const Client& c) { return c.uid == uid; }));
    if (same >= limits_.per_user) {
      return "too many connections: uid " + std::to_string(uid) + " has " + std::to_string(same) +
             ", the most one user may have";
    }
  }
  return "";
}

void Server::admit(int fd) {
  std::string who;
  uid_t uid = 0;
  const Access access = peer_access(fd, policy_, who, &uid);
  if (access == Access::none) {
    refuse(fd, kPermissionDenied,
           "permission denied: " + who + " is neither root nor in cncd's read or control group");
    refusal_log_.log(spdlog::level::info, "control connection refused: " + who);
    return;
  }
  const bool capped = uid != 0 && uid != policy_.owner;
  if (const std::string reason = refusal(access, uid, capped); !reason.empty()) {
    refuse(fd, kTooManyConnections, reason);
    refusal_log_.log(spdlog::level::warn, "control connection refused: " + who + ": " + reason);
    return;
  }
  Client client;
  client.fd = fd;
  client.uid = uid;
  client.capped = capped;
  client.session.access = access;
  client.session.peer = who;
  client.session.connection = ++last_connection_;
  client.event_seq = events_.last_seq();
  clients_.push_back(std::move(client));
}

// Unfinished lines past kInputBudgetBytes in all: the longest go, each with the reason, until
// the rest fit. Complete lines need no budget: at most kReadAheadBytes of them are read ahead.
void Server::bound_input() {
  std::size_t total = 0;
  for (const auto& client : clients_)
    total += client.in.size() - client.complete;
  while (total > kInputBudgetBytes) {
    const auto longest =
        std::max_element(clients_.begin(), clients_.end(), [](const Client& a, const Client& b) {
          return a.in.size() - a.complete < b.in.size() - b.complete;
        });
    const std::size_t unfinished = longest->in.size() - longest->complete;
    total -= unfinished;
    const nlohmann::json error = {
        {"jsonrpc", "2.0"},
        {"id", nullptr},
        {"error", RpcDispatcher::error_object(
                      kRequestTooLarge, "unfinished request line of " + std::to_string(unfinished) +
                                            " bytes dropped: cncd keeps at most " +
                                            std::to_string(kInputBudgetBytes >> 20) +
                                            " MiB of unfinished lines across all connections")}};
    longest->in.resize(longest->complete);
    longest->in.shrink_to_fit();
    longest->out += error.dump() + "\n";
    stop_reading(*longest);
    client_log_.log(spdlog::level::warn, "control client closed: unfinished request line of " +
                                             std::to_string(unfinished) +
                                             " bytes past the input budget");
  }
}

}  // namespace cncd::daemon
