// Estop through cncd-web's /ws while 50 browsers watch: cncd on config/examples/sim_mm.ini and
// cncd-web in front of it; a WebSocket client holding an operator's API key runs a long
// program and sends machine.estop, timing each estop's answer; then the same with CLIENTS more
// WebSockets each subscribed to the whole status every 50 ms. Between samples the machine is
// reset, turned on and the program run again. For each phase also the servo thread's overruns
// (status rt.overruns, read on cncd's Unix socket) while the program runs for WINDOW seconds.
// The phases alternate ROUNDS times (alone, watched, alone, ...), so that a drift of the
// host's noise falls on both. With RT_CPU >= 0 the servo thread is pinned there ([CNCD]
// RT_CPU) and everything else (cncd's other threads, cncd-web, this bench) kept off it, as a
// machine with a CPU set aside for the servo thread runs. Prints figures; never fails on timing.
//
//   cncd_ws_estop_bench [SAMPLES=100] [WINDOW_S=10] [CLIENTS=50] [ROUNDS=3] [RT_CPU=-1]
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <regex>
#include <sstream>

#include "../daemon/bench_client.hpp"

namespace {

using namespace cncd::bench;
using nlohmann::json;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

pid_t daemon_pid = -1;
pid_t web_pid = -1;
void end_children() {
  for (const pid_t pid : {web_pid, daemon_pid}) {
    if (pid > 0) {
      kill(pid, SIGTERM);
      waitpid(pid, nullptr, 0);
    }
  }
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "cncd_ws_estop_bench: %s\n", what.c_str());
  std::exit(1);
}

int free_port() {
  net::io_context io;
  tcp::acceptor acceptor(io, tcp::endpoint(net::ip::make_address("127.0.0.1"), 0));
  return acceptor.local_endpoint().port();
}

// A WebSocket to cncd-web's /ws that authenticates with an API key, as scripts do.
class WsClient {
 public:
  WsClient(net::io_context& io, int port, const std::string& key) : ws_(io) {
    tcp::resolver resolver(io);
    net::connect(ws_.next_layer(), resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.next_layer().set_option(tcp::no_delay(true));
    ws_.set_option(websocket::stream_base::decorator([key](websocket::request_type& request) {
      request.set(beast::http::field::authorization, "Bearer " + key);
    }));
    ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws");
    ws_.text(true);
  }

  void send(const std::string& method, const json& params = nullptr) {
    json request{{"jsonrpc", "2.0"}, {"id", ++id_}, {"method", method}};
    if (!params.is_null()) request["params"] = params;
    ws_.write(net::buffer(request.dump()));
  }

  // The answer to the last request sent; notifications are passed over.
  json answer() {
    for (;;) {
      buffer_.clear();
      ws_.read(buffer_);
      json message = json::parse(beast::buffers_to_string(buffer_.data()), nullptr, false);
      if (message.is_object() && message.value("id", json()) == json(id_)) return message;
    }
  }

  json call(const std::string& method, const json& params = nullptr) {
    send(method, params);
    json message = answer();
    if (!message.contains("result")) fail(method + " through /ws refused: " + message.dump());
    return message["result"];
  }

  // Reads whatever comes, counting frames, until the stream is closed under it.
  void read_forever(long& frames) {
    ws_.async_read(buffer_, [this, &frames](beast::error_code ec, std::size_t) {
      if (ec) return;
      ++frames;
      buffer_.clear();
      read_forever(frames);
    });
  }

 private:
  websocket::stream<tcp::socket> ws_;
  beast::flat_buffer buffer_;
  long id_ = 0;
};

// The daemon's status, read on its Unix socket.
json status(Conn& c, const char* fields) {
  send_line(c, std::string(R"({"jsonrpc":"2.0","id":1,"method":"status.get","params":)") +
                   R"({"fields":[)" + fields + "]}}");
  const std::string line = read_answer(c);
  json answer = json::parse(line, nullptr, false);
  if (!answer.is_object() || !answer.contains("result")) fail("status.get: " + line);
  return answer["result"];
}

template <typename Predicate>
json wait_for(Conn& c, const char* fields, Predicate done, const char* what, int seconds = 30) {
  const auto deadline = Clock::now() + std::chrono::seconds(seconds);
  for (;;) {
    json s = status(c, fields);
    if (done(s)) return s;
    if (Clock::now() > deadline)
      fail(std::string("timed out waiting for ") + what + ": " + s.dump());
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// Out of estop, on, homed, and the program running.
void start_run(WsClient& control, Conn& c) {
  control.call("machine.reset");
  control.call("machine.on");
  const json homed = status(c, R"("homed")");
  if (!std::all_of(homed["homed"].begin(), homed["homed"].end(),
                   [](auto& h) { return h == true; })) {
    control.call("machine.home");
    wait_for(
        c, R"("homed","motion")",
        [](const json& s) {
          return s["motion"] == "idle" && std::all_of(s["homed"].begin(), s["homed"].end(),
                                                      [](auto& h) { return h == true; });
        },
        "homing");
  }
  control.call("program.run");
  wait_for(
      c, R"("exec","motion")",
      [](const json& s) { return s["exec"] == "running" && s["motion"] == "moving"; },
      "the program moving");
}

struct Phase {
  std::string name;
  std::vector<double> estop_ms;
  long overruns = 0;
  std::vector<long> round_overruns;  // each round's window
  long cycles = 0;
  double window_s = 0;
  long frames = 0;
  double frames_window_s = 0;
};

// Adds one window of overruns and `samples` estops to `phase`.
void measure(Phase& phase, WsClient& control, Conn& c, int samples, int window_s, int round) {
  start_run(control, c);
  const json before = status(c, R"("rt")")["rt"];
  const auto t0 = Clock::now();
  std::this_thread::sleep_for(std::chrono::seconds(window_s));
  const json after = status(c, R"("rt","exec")");
  phase.window_s += std::chrono::duration<double>(Clock::now() - t0).count();
  const long overruns = after["rt"]["overruns"].get<long>() - before["overruns"].get<long>();
  phase.overruns += overruns;
  phase.round_overruns.push_back(overruns);
  phase.cycles += after["rt"]["cycles"].get<long>() - before["cycles"].get<long>();
  if (after["exec"] != "running") fail("the program ended within the window: make it longer");
  std::mt19937 random(24 + round);  // the same delays in both phases of a round
  std::uniform_int_distribution<int> delay_ms(10, 60);
  for (int i = 0; i < samples; ++i) {
    if (i > 0) start_run(control, c);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(random)));
    const auto sent = Clock::now();
    control.send("machine.estop");
    const json answer = control.answer();
    phase.estop_ms.push_back(
        std::chrono::duration<double, std::milli>(Clock::now() - sent).count());
    if (!answer.contains("result")) fail("machine.estop refused: " + answer.dump());
    wait_for(
        c, R"("state","motion")",
        [](const json& s) { return s["state"] == "estop" && s["motion"] == "idle"; },
        "estop at rest");
  }
}

std::string make_user(const std::string& ini) {
  const std::string cli = std::string(CNCD_WEB_BINARY) + " --ini " + ini;
  FILE* add = popen((cli + " user add bench --role operator >/dev/null").c_str(), "w");
  std::fputs("bench-password-1\n", add);
  if (pclose(add) != 0) fail("cncd-web user add failed");
  FILE* key = popen((cli + " key add bench").c_str(), "r");
  std::string out;
  char chunk[512];
  while (std::fgets(chunk, sizeof chunk, key) != nullptr)
    out += chunk;
  if (pclose(key) != 0) fail("cncd-web key add failed: " + out);
  std::smatch found;
  if (!std::regex_search(out, found, std::regex("cncd_[A-Za-z0-9_-]+"))) fail("no key in " + out);
  return found.str();
}

pid_t start_web(const std::string& ini, const std::string& sock, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    dup2(fd, 1);
    dup2(fd, 2);
    execl(CNCD_WEB_BINARY, CNCD_WEB_BINARY, "--ini", ini.c_str(), "--socket", sock.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// The chance that, were the watchers to make no difference, `with` or more of the `with +
// without` overruns would fall in the watched windows, which had `share` of the cycles: the
// binomial tail. Small (under 0.05) says the watchers add overruns; near 0.5 or above says the
// counts differ by no more than chance.
double chance_of_at_least(long with, long without, double share) {
  const long n = with + without;
  if (n == 0) return 1.0;
  double tail = 0;
  for (long k = with; k <= n; ++k) {
    const double log_term =
        std::lgamma(static_cast<double>(n) + 1) - std::lgamma(static_cast<double>(k) + 1) -
        std::lgamma(static_cast<double>(n - k) + 1) + static_cast<double>(k) * std::log(share) +
        static_cast<double>(n - k) * std::log1p(-share);
    tail += std::exp(log_term);
  }
  return std::min(1.0, tail);
}

void print(const Phase& p) {
  std::printf("%-22s %9.2f ms %9.2f ms %9.2f ms %9ld %11ld %9.1f\n", p.name.c_str(),
              percentile(p.estop_ms, 0.5), percentile(p.estop_ms, 0.99),
              percentile(p.estop_ms, 1.0), p.overruns, p.cycles,
              p.frames_window_s > 0 ? static_cast<double>(p.frames) / p.frames_window_s : 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  const int samples = argc > 1 ? std::atoi(argv[1]) : 100;
  const int window_s = argc > 2 ? std::atoi(argv[2]) : 10;
  const int clients = argc > 3 ? std::atoi(argv[3]) : 50;
  const int rounds = std::max(1, argc > 4 ? std::atoi(argv[4]) : 3);
  const int rt_cpu = argc > 5 ? std::atoi(argv[5]) : -1;
  namespace fs = std::filesystem;
  const fs::path dir = bench_dir({".var", ".tbl"});
  const fs::path programs = dir / "programs";
  fs::create_directories(programs);
  const int port = free_port();
  std::stringstream text;
  text << std::ifstream(fs::path(CNCD_SOURCE_DIR) / "config/examples/sim_mm.ini").rdbuf();
  std::string ini = text.str();
  const std::string prefix = "\nPROGRAM_PREFIX = ";
  if (const auto at = ini.find(prefix); at != std::string::npos)
    ini.replace(at + 1, ini.find('\n', at + 1) - at - 1, "PROGRAM_PREFIX = " + programs.string());
  ini += "\n[WEB]\nPORT = " + std::to_string(port) + "\nPROGRAM_DIR = " + programs.string() +
         "\nUSERS_FILE = " + (dir / "web-users").string() + "\n";
  if (rt_cpu >= 0) {
    const std::string section = "[CNCD]\n";
    const auto at = ini.find(section);
    if (at == std::string::npos) fail("sim_mm.ini has no [CNCD] section");
    ini.insert(at + section.size(), "RT_CPU = " + std::to_string(rt_cpu) + "\n");
    // Children inherit the mask; the servo thread pins itself to RT_CPU.
    cpu_set_t others;
    CPU_ZERO(&others);
    for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
      if (cpu != rt_cpu) CPU_SET(cpu, &others);
    }
    if (sched_setaffinity(0, sizeof others, &others) != 0) fail("cannot keep off CPU RT_CPU");
  }
  std::ofstream(dir / "sim_mm.ini") << ini;
  // 1 mm moves at 50 mm/s: some 20 ms a line, an hour in all; never ends within the bench.
  write_program(programs / "bench.ngc", 200'000);
  const std::string sock = (dir / "cncd.sock").string();
  const std::string ini_path = (dir / "sim_mm.ini").string();
  std::atexit(end_children);
  daemon_pid =
      start_cncd(dir, sock, {"--state-dir", (dir / "state").string(), "--log-level", "error"});
  Conn c = connect_when_up(sock);
  const std::string key = make_user(ini_path);
  web_pid = start_web(ini_path, sock, (dir / "cncd-web.log").string());

  net::io_context io;
  std::unique_ptr<WsClient> control;
  for (int i = 0; i < 500 && !control; ++i) {
    try {
      control = std::make_unique<WsClient>(io, port, key);
    } catch (const std::exception&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  if (!control) fail("cncd-web did not start; see " + (dir / "cncd-web.log").string());
  control->call("lease.take", {{"force", true}});
  control->call("program.open", {{"path", "bench.ngc"}});
  wait_for(
      c, R"("program")",
      [](const json& s) { return s["program"]["path"] != "" && s["program"]["opening"] == ""; },
      "the program open", 120);

  // The watchers: each its own WebSocket and upstream connection, read on one thread that
  // runs only while they are subscribed (the main thread subscribes them in between).
  net::io_context watch_io;
  std::vector<std::unique_ptr<WsClient>> watchers;
  std::vector<long> frames(static_cast<std::size_t>(clients), 0);
  for (int i = 0; i < clients; ++i) {
    watchers.push_back(std::make_unique<WsClient>(watch_io, port, key));
    watchers.back()->read_forever(frames[static_cast<std::size_t>(i)]);
  }
  Phase alone;
  alone.name = "alone";
  Phase watched;
  watched.name = std::to_string(clients) + " subscribers";
  const int per_round = std::max(1, samples / rounds);
  for (int round = 0; round < rounds; ++round) {
    measure(alone, *control, c, per_round, window_s, round);
    for (auto& w : watchers)
      w->send("status.subscribe", {{"interval_ms", 50}});
    // The counts are read while the watchers' thread is not running.
    const long frames_before = std::accumulate(frames.begin(), frames.end(), 0L);
    const auto frames_from = Clock::now();
    watch_io.restart();
    std::thread watch_thread([&] { watch_io.run(); });
    std::this_thread::sleep_for(std::chrono::seconds(1));
    measure(watched, *control, c, per_round, window_s, round);
    watch_io.stop();
    watch_thread.join();
    watched.frames += std::accumulate(frames.begin(), frames.end(), 0L) - frames_before;
    watched.frames_window_s += std::chrono::duration<double>(Clock::now() - frames_from).count();
    for (auto& w : watchers)
      w->send("status.unsubscribe");
  }

  const json rt = status(c, R"("rt")")["rt"];
  std::printf(
      "estop through cncd-web's /ws while a program runs: %d rounds of %d samples a phase; "
      "overruns over %d s of the run a round; servo thread realtime %s, memory locked %s, "
      "CPU %s\n",
      rounds, per_round, window_s, rt.value("realtime", false) ? "yes" : "no",
      rt.value("memory_locked", false) ? "yes" : "no",
      rt_cpu >= 0 ? std::to_string(rt_cpu).c_str() : "any");
  std::printf("%-22s %12s %12s %12s %9s %11s %9s\n", "phase", "estop p50", "estop p99", "estop max",
              "overruns", "cycles", "frames/s");
  print(alone);
  print(watched);
  if (alone.overruns > 0)
    std::printf("overruns with/without: %.2f\n",
                static_cast<double>(watched.overruns) / static_cast<double>(alone.overruns));
  else
    std::printf("overruns with/without: %ld/%ld (no ratio: none without)\n", watched.overruns,
                alone.overruns);
  std::printf("overruns a round, alone:");
  for (const long n : alone.round_overruns)
    std::printf(" %ld", n);
  std::printf("; watched:");
  for (const long n : watched.round_overruns)
    std::printf(" %ld", n);
  const double share = static_cast<double>(watched.cycles) /
                       static_cast<double>(std::max(1L, watched.cycles + alone.cycles));
  std::printf(
      "\nchance of %ld or more of the %ld overruns in the watched windows if the watchers "
      "made no difference: %.2f\n",
      watched.overruns, watched.overruns + alone.overruns,
      chance_of_at_least(watched.overruns, alone.overruns, share));
  std::printf("estop p99 with/without: %.2f\n",
              percentile(watched.estop_ms, 0.99) / percentile(alone.estop_ms, 0.99));
  watchers.clear();
  control.reset();
  end_children();
  daemon_pid = web_pid = -1;
  fs::remove_all(dir);
  return 0;
}
