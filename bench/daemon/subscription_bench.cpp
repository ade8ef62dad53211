// Subscription latency with many clients: the time from a state change being commanded to
// each subscriber receiving the update, against a status.get round trip measured in the same
// run as the reference. Prints figures; never fails on timing.
//
//   cncd_subscription_bench [CLIENTS=256] [ROUNDS=20] [INTERVAL_MS=10]
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

namespace {

using Clock = std::chrono::steady_clock;

struct Conn {
  int fd = -1;
  std::string buffer;
};

int connect_to(const std::string& path) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, path.c_str(), sizeof addr.sun_path - 1);
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    close(fd);
    return -1;
  }
  // Reads never block: every wait is a poll with a time limit.
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK);
  return fd;
}

void send_line(const Conn& c, const std::string& line) {
  const std::string data = line + "\n";
  if (send(c.fd, data.data(), data.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(data.size())) {
    std::perror("send");
    std::exit(1);
  }
}

// Reads whatever is there; returns complete lines.
std::vector<std::string> read_lines(Conn& c) {
  char chunk[65536];
  const ssize_t n = read(c.fd, chunk, sizeof chunk);
  if (n > 0) c.buffer.append(chunk, static_cast<std::size_t>(n));
  std::vector<std::string> lines;
  std::size_t nl;
  while ((nl = c.buffer.find('\n')) != std::string::npos) {
    lines.push_back(c.buffer.substr(0, nl));
    c.buffer.erase(0, nl + 1);
  }
  return lines;
}

// The next answer (a line with an "id") on `c`, skipping notifications.
void read_answer(Conn& c) {
  const auto deadline = Clock::now() + std::chrono::seconds(10);
  while (Clock::now() < deadline) {
    pollfd p{c.fd, POLLIN, 0};
    poll(&p, 1, 100);
    for (const auto& line : read_lines(c)) {
      if (line.find("\"id\"") != std::string::npos) return;
    }
  }
  std::fprintf(stderr, "no answer from cncd within 10 s\n");
  std::exit(1);
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main(int argc, char** argv) {
  const int clients = argc > 1 ? std::atoi(argv[1]) : 256;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 20;
  const int interval_ms = argc > 3 ? std::atoi(argv[3]) : 10;
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("cncd-bench-" + std::to_string(getpid()));
  fs::create_directories(dir);
  for (const char* ext : {".ini", ".var", ".tbl"}) {
    fs::copy_file(fs::path(CNCD_SOURCE_DIR) / "config/examples" / (std::string("sim_mm") + ext),
                  dir / (std::string("sim_mm") + ext), fs::copy_options::overwrite_existing);
  }
  const std::string sock = (dir / "cncd.sock").string();
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string ini = (dir / "sim_mm.ini").string();
    execl(CNCD_BINARY, CNCD_BINARY, "--ini", ini.c_str(), "--socket", sock.c_str(), "--log-level",
          "warn", static_cast<char*>(nullptr));
    _exit(127);
  }
  Conn control;
  for (int i = 0; i < 500 && control.fd < 0; ++i) {
    control.fd = connect_to(sock);
    if (control.fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (control.fd < 0) {
    std::fprintf(stderr, "cncd did not start\n");
    return 1;
  }
  std::vector<Conn> subs(static_cast<std::size_t>(clients));
  for (auto& c : subs) {
    c.fd = connect_to(sock);
    send_line(c, R"({"jsonrpc":"2.0","id":1,"method":"status.subscribe","params":{"interval_ms":)" +
                     std::to_string(interval_ms) + R"(,"fields":["state"]}})");
    read_answer(c);
  }
  // Reference: plain request round trips on one connection.
  std::vector<double> round_trip_ms;
  for (int i = 0; i < 200; ++i) {
    const auto t0 = Clock::now();
    send_line(control,
              R"({"jsonrpc":"2.0","id":2,"method":"status.get","params":{"fields":["state"]}})");
    read_answer(control);
    round_trip_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  for (auto& c : subs)
    read_lines(c);  // drop the first, full updates

  std::vector<double> latency_ms;
  std::vector<pollfd> fds(subs.size());
  for (int r = 0; r < rounds; ++r) {
    // Changes spaced wider than the interval, as independent events are: updates are limited
    // to one an interval per client, so back-to-back changes would measure that limit instead.
    std::this_thread::sleep_for(std::chrono::milliseconds(2 * interval_ms + 7 * (r % 5)));
    for (auto& c : subs)
      read_lines(c);
    const bool to_estop = r % 2 == 1;
    const std::string want = to_estop ? "\"state\":\"estop\"" : "\"state\":\"off\"";
    const auto t0 = Clock::now();
    send_line(control, std::string(R"({"jsonrpc":"2.0","id":3,"method":")") +
                           (to_estop ? "machine.estop" : "machine.reset") + "\"}");
    read_answer(control);
    std::vector<bool> seen(subs.size(), false);
    std::size_t remaining = subs.size();
    while (remaining > 0) {
      for (std::size_t i = 0; i < subs.size(); ++i)
        fds[i] = {subs[i].fd, POLLIN, 0};
      if (poll(fds.data(), fds.size(), 5000) <= 0) break;
      for (std::size_t i = 0; i < subs.size(); ++i) {
        if (!(fds[i].revents & POLLIN)) continue;
        for (const auto& line : read_lines(subs[i])) {
          if (!seen[i] && line.find(want) != std::string::npos) {
            seen[i] = true;
            --remaining;
            latency_ms.push_back(
                std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
          }
        }
      }
    }
  }
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  fs::remove_all(dir);

  const double ref = percentile(round_trip_ms, 0.5);
  std::printf("clients=%d rounds=%d interval_ms=%d updates=%zu\n", clients, rounds, interval_ms,
              latency_ms.size());
  std::printf("status.get round trip (reference): p50 %.3f ms  p99 %.3f ms\n", ref,
              percentile(round_trip_ms, 0.99));
  std::printf("change -> update at every client:  p50 %.3f ms  p99 %.3f ms  max %.3f ms\n",
              percentile(latency_ms, 0.5), percentile(latency_ms, 0.99),
              percentile(latency_ms, 1.0));
  std::printf("update p50 / round-trip p50 = %.1f\n",
              ref > 0 ? percentile(latency_ms, 0.5) / ref : 0);
  return 0;
}
