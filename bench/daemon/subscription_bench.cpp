// Subscription latency with many clients: the time from a state change being commanded to
// each subscriber receiving the update, against a status.get round trip measured in the same
// run as the reference. Prints figures; never fails on timing.
//
//   cncd_subscription_bench [CLIENTS=256] [ROUNDS=20] [INTERVAL_MS=10]
#include <signal.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "bench_client.hpp"

namespace {

using namespace cncd::bench;

void send_or_exit(const Conn& c, const std::string& line) {
  if (!send_line(c, line)) {
    std::perror("send");
    std::exit(1);
  }
}

void answer_or_exit(Conn& c) {
  if (read_answer(c).empty()) {
    std::fprintf(stderr, "no answer from cncd within 10 s\n");
    std::exit(1);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const int clients = argc > 1 ? std::atoi(argv[1]) : 256;
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 20;
  const int interval_ms = argc > 3 ? std::atoi(argv[3]) : 10;
  namespace fs = std::filesystem;
  const fs::path dir = bench_dir({".ini", ".var", ".tbl"});
  const std::string sock = (dir / "cncd.sock").string();
  const pid_t pid = start_cncd(dir, sock, {"--log-level", "warn"});
  Conn control = connect_when_up(sock);
  std::vector<Conn> subs(static_cast<std::size_t>(clients));
  for (auto& c : subs) {
    c.fd = connect_to(sock);
    send_or_exit(c,
                 R"({"jsonrpc":"2.0","id":1,"method":"status.subscribe","params":{"interval_ms":)" +
                     std::to_string(interval_ms) + R"(,"fields":["state"]}})");
    answer_or_exit(c);
  }
  // Reference: plain request round trips on one connection.
  std::vector<double> round_trip_ms;
  for (int i = 0; i < 200; ++i) {
    const auto t0 = Clock::now();
    send_or_exit(control,
                 R"({"jsonrpc":"2.0","id":2,"method":"status.get","params":{"fields":["state"]}})");
    answer_or_exit(control);
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
    send_or_exit(control, std::string(R"({"jsonrpc":"2.0","id":3,"method":")") +
                              (to_estop ? "machine.estop" : "machine.reset") + "\"}");
    answer_or_exit(control);
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
