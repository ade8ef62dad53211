// Stop latency under load: the time from sending machine.estop or jog.stop to its answer,
// while another client opens a large program over and over (each open checks the whole
// program on cncd's worker thread, and the estop cancels the check under way), the first
// open's time estimate runs in the background, and optionally a third client floods the
// socket with batches of status.get. Each try waits until an open is being checked, jogs X,
// stops the jog, waits for the axis to stop and estops. Prints figures; never fails on timing.
//
//   cncd_open_stop_bench [TRIES=200] [LINES=2000000] [FLOOD=0|1]
#include <signal.h>
#include <sys/wait.h>

#include <atomic>
#include <fstream>
#include <sstream>

#include "bench_client.hpp"

namespace {

using namespace cncd::bench;

std::string request(const char* method, const std::string& params = "") {
  return std::string(R"({"jsonrpc":"2.0","id":1,"method":")") + method + "\"" +
         (params.empty() ? "" : ",\"params\":" + params) + "}";
}

// Round trip of one request, in ms; exits when no answer comes.
double timed(Conn& c, const std::string& line) {
  const auto t0 = Clock::now();
  send_line(c, line);
  if (read_answer(c).empty()) {
    std::fprintf(stderr, "no answer from cncd within 10 s to %s\n", line.c_str());
    std::exit(1);
  }
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void print(const char* what, const std::vector<double>& ms) {
  std::printf("%-34s p50 %7.3f ms  p99 %7.3f ms  max %7.3f ms  (n=%zu)\n", what,
              percentile(ms, 0.5), percentile(ms, 0.99), percentile(ms, 1.0), ms.size());
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

int main(int argc, char** argv) {
  const int tries = argc > 1 ? std::atoi(argv[1]) : 200;
  const long lines = argc > 2 ? std::atol(argv[2]) : 2'000'000;
  const bool flood = argc > 3 && std::atoi(argv[3]) != 0;
  namespace fs = std::filesystem;
  const fs::path dir = bench_dir({".var", ".tbl"});
  const fs::path examples = fs::path(CNCD_SOURCE_DIR) / "config/examples";
  // Programs open from the bench's own directory.
  std::string ini = slurp(examples / "sim_mm.ini");
  if (const auto at = ini.find("\nPROGRAM_PREFIX = "); at != std::string::npos)
    ini.replace(at + 1, ini.find('\n', at + 1) - at - 1, "PROGRAM_PREFIX = .");
  std::ofstream(dir / "sim_mm.ini") << ini;
  const fs::path program = dir / "big.ngc";
  write_program(program, lines);
  const std::string sock = (dir / "cncd.sock").string();
  const pid_t pid = start_cncd(dir, sock, {"--state-dir", dir.string(), "--log-level", "error"});
  Conn control = connect_when_up(sock);
  std::vector<double> reference_ms;
  for (int i = 0; i < 50; ++i)
    reference_ms.push_back(timed(control, request("machine.estop")));

  // The opener: program.open of the big program, again as soon as it is answered (a little
  // later when refused at once, as while the machine moves).
  std::atomic<bool> done{false};
  std::atomic<bool> first_open_done{false};
  std::atomic<int> opened{0};
  std::atomic<int> cancelled{0};
  std::atomic<int> refused{0};
  double first_open_s = 0;
  std::thread opener([&] {
    Conn c;
    c.fd = connect_to(sock);
    const std::string open = request("program.open", "{\"path\":\"" + program.string() + "\"}");
    while (!done.load()) {
      const auto t0 = Clock::now();
      if (!send_line(c, open)) break;
      const std::string answer = read_answer(c, std::chrono::seconds(60));
      if (answer.find("\"result\"") != std::string::npos) {
        opened.fetch_add(1);
      } else if (answer.find("1009") != std::string::npos) {
        cancelled.fetch_add(1);
      } else {
        if (refused.fetch_add(1) == 0) std::fprintf(stderr, "first refusal: %s\n", answer.c_str());
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      if (!first_open_done.load()) {
        first_open_s = std::chrono::duration<double>(Clock::now() - t0).count();
        first_open_done.store(true);
      }
    }
    close(c.fd);
  });
  // The flooder: batches of 32 status.get, as fast as the daemon answers them.
  std::atomic<long> flooded{0};
  std::thread flooder([&] {
    if (!flood) return;
    Conn c;
    c.fd = connect_to(sock);
    std::string batch = "[";
    for (int i = 0; i < 32; ++i)
      batch += (i > 0 ? "," : "") + request("status.get");
    batch += "]";
    while (!done.load()) {
      for (int i = 0; i < 8; ++i)
        send_line(c, batch);
      for (int i = 0; i < 8 && !done.load(); ++i) {
        if (read_answer(c, std::chrono::seconds(1)).empty()) break;
        flooded.fetch_add(32);
      }
    }
    close(c.fd);
  });
  // The first open runs its check to the end, and its estimate then runs meanwhile.
  while (!first_open_done.load())
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const auto opening = [&] {
    send_line(control, request("status.get", R"({"fields":["program"]})"));
    return read_answer(control).find("\"opening\":\"/") != std::string::npos;
  };
  int stopped_while_opening = 0;

  std::vector<double> estop_ms;
  std::vector<double> jog_stop_ms;
  for (int i = 0; i < tries; ++i) {
    timed(control, request("machine.reset"));
    timed(control, request("machine.on"));
    while (!opening())
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    // Unhomed, as the jog that ran past the travel: back and forth about the start.
    const std::string velocity = i % 2 == 0 ? "20" : "-20";
    timed(control, request("jog.start", "{\"axis\":\"X\",\"velocity\":" + velocity + "}"));
    std::this_thread::sleep_for(std::chrono::milliseconds(5 + i % 7));
    jog_stop_ms.push_back(timed(control, request("jog.stop", "{\"axis\":\"X\"}")));
    for (;;) {
      send_line(control, request("status.get", R"({"fields":["motion"]})"));
      if (read_answer(control).find("\"idle\"") != std::string::npos) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    stopped_while_opening += opening() ? 1 : 0;
    estop_ms.push_back(timed(control, request("machine.estop")));
  }
  done.store(true);
  // The opener waits for its answer: an estop cancels the check under way.
  timed(control, request("machine.estop"));
  opener.join();
  flooder.join();
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  fs::remove_all(dir);

  std::printf("tries=%d program=%ld lines flood=%s; first open answered after %.2f s\n", tries,
              lines, flood ? "yes" : "no", first_open_s);
  std::printf(
      "opens: %d opened, %d cancelled, %d refused; jog stopped and open still checked "
      "before the estop in %d of %d tries; status.get flooded: %ld\n",
      opened.load(), cancelled.load(), refused.load(), stopped_while_opening, tries,
      flooded.load());
  print("machine.estop, idle daemon:", reference_ms);
  print("jog.stop while opening:", jog_stop_ms);
  print("machine.estop while opening:", estop_ms);
  return 0;
}
