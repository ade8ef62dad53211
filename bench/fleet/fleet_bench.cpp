// The fleet page's sizing: MACHINES simulated machines publish cncd-telemetry's state payload
// (retained, QoS 1, as cncd-telemetry does) at HZ each into one local mosquitto, evenly spread
// over each period; cncd-fleet reads the broker and one WebSocket client reads the page's
// frames. Over SECONDS (after 3 s to settle) it prints the messages and frames, the latency
// from each publish (the state's "time") to the WebSocket frame that carries it (p50, p99,
// max; a state superseded within one push counts only as its latest), and cncd-fleet's and
// mosquitto's CPU (utime + stime from /proc, percent of one core) and resident memory.
// Prints figures; never fails on them.
//
//   cncd_fleet_bench [MACHINES=100] [HZ=5] [SECONDS=20] [PUSH_MS=50]
#include <mosquitto.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "../daemon/bench_client.hpp"

namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;
namespace net = boost::asio;
namespace websocket = boost::beast::websocket;

std::vector<pid_t> children;
void end_children() {
  for (auto it = children.rbegin(); it != children.rend(); ++it) {
    kill(*it, SIGTERM);
    waitpid(*it, nullptr, 0);
  }
}

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "cncd_fleet_bench: %s\n", what.c_str());
  end_children();
  std::exit(1);
}

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

int free_port() {
  net::io_context io;
  net::ip::tcp::acceptor acceptor(io, {net::ip::make_address("127.0.0.1"), 0});
  return acceptor.local_endpoint().port();
}

pid_t spawn(std::vector<std::string> args, const std::string& log) {
  const pid_t pid = cncd::bench::spawn_process(std::move(args), log);
  children.push_back(pid);
  return pid;
}

bool listening(int port) {
  net::io_context io;
  net::ip::tcp::socket s(io);
  boost::system::error_code ec;
  s.connect({net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)}, ec);
  return !ec;
}

void wait_listening(int port, const char* what) {
  for (int i = 0; i < 1000; ++i) {
    if (listening(port)) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  fail(std::string(what) + " did not listen");
}

// CPU seconds (user + system) and resident KiB of `pid`.
std::pair<double, long> usage(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), {});
  std::istringstream fields(text.substr(text.rfind(')') + 2));
  std::string field;
  double ticks = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14 || i == 15) ticks += std::stod(field);
  }
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  long rss = 0;
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmRSS:", 0) == 0) rss = std::stol(line.substr(6));
  }
  return {ticks / static_cast<double>(sysconf(_SC_CLK_TCK)), rss};
}

json state(int i, double progress) {
  const std::string id = "mill-" + std::to_string(i);
  return {{"machine", id},
          {"cncd", "connected"},
          {"state", "on"},
          {"mode", "auto"},
          {"exec", "running"},
          {"program",
           {{"path", "/srv/ngc/part-" + std::to_string(i % 17) + ".ngc"},
            {"line", static_cast<int>(progress * 4000)},
            {"total_lines", 4000},
            {"progress", progress},
            {"estimated_s", 600.0},
            {"remaining_s", 600.0 * (1 - progress)},
            {"result", ""}}},
          {"tool", 3},
          {"spindle", {{"rpm", 12000}, {"commanded_rpm", 12000}, {"direction", 1}}},
          {"overrides", {{"feed", 1}, {"rapid", 1}, {"spindle", 1}}},
          {"wait", nullptr},
          {"fault", ""},
          {"last_error", nullptr},
          {"parts", i},
          {"dashboard", "http://" + id + ".shop:8080/"}};
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  const int machines = argc > 1 ? std::atoi(argv[1]) : 100;
  const double hz = argc > 2 ? std::atof(argv[2]) : 5;
  const int seconds = argc > 3 ? std::atoi(argv[3]) : 20;
  const int push_ms = argc > 4 ? std::atoi(argv[4]) : 50;
  if (!std::filesystem::exists("/usr/sbin/mosquitto"))
    fail("mosquitto is not installed (scripts/setup.sh --with-broker)");
  const auto dir =
      std::filesystem::temp_directory_path() / ("cncd-fleet-bench-" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const int broker_port = free_port();
  std::ofstream(dir / "mosquitto.conf")
      << "listener " << broker_port << " 127.0.0.1\nallow_anonymous true\n"
      << "persistence false\nmax_queued_messages 100000\nset_tcp_nodelay true\n";
  const pid_t broker = spawn({"/usr/sbin/mosquitto", "-c", (dir / "mosquitto.conf").string()},
                             (dir / "mosquitto.log").string());
  wait_listening(broker_port, "mosquitto");
  const int page_port = free_port();
  const pid_t fleet = spawn(
      {CNCD_FLEET_BINARY, "--broker", "127.0.0.1:" + std::to_string(broker_port), "--listen",
       "127.0.0.1:" + std::to_string(page_port), "--www", CNCD_FLEET_WWW, "--max-machines",
       std::to_string(machines + 10), "--push-ms", std::to_string(push_ms), "--log-level", "warn"},
      (dir / "fleet.log").string());
  wait_listening(page_port, "cncd-fleet");

  // The browser: every update frame's rows, each one's latency from its state's "time".
  std::mutex mutex;
  std::vector<double> latencies;
  std::atomic<bool> measuring{false}, done{false};
  std::atomic<long> frames{0}, rows{0};
  std::thread reader([&] {
    net::io_context io;
    websocket::stream<net::ip::tcp::socket> ws(io);
    ws.next_layer().connect(
        {net::ip::make_address("127.0.0.1"), static_cast<unsigned short>(page_port)});
    ws.handshake("127.0.0.1", "/ws");
    boost::beast::flat_buffer buffer;
    boost::system::error_code ec;
    while (!done) {
      ws.read(buffer, ec);
      if (ec) break;
      const double now = unix_now();
      const json frame =
          json::parse(boost::beast::buffers_to_string(buffer.data()), nullptr, false);
      buffer.consume(buffer.size());
      if (!measuring || !frame.is_object() || frame["type"] != "update") continue;
      ++frames;
      std::lock_guard lock(mutex);
      for (const auto& m : frame["machines"]) {
        if (!m["time"].is_number()) continue;
        ++rows;
        latencies.push_back((now - m["time"].get<double>()) * 1000);
      }
    }
  });

  mosquitto_lib_init();
  mosquitto* pub = mosquitto_new(nullptr, true, nullptr);
  if (mosquitto_connect(pub, "127.0.0.1", broker_port, 30) != MOSQ_ERR_SUCCESS)
    fail("cannot connect to mosquitto");
  mosquitto_loop_start(pub);

  const auto period = std::chrono::duration<double>(1.0 / hz);
  const auto step = period / machines;
  const auto start = Clock::now();
  const auto warm = start + std::chrono::seconds(3);
  const auto end = warm + std::chrono::seconds(seconds);
  std::pair<double, long> fleet_before{}, broker_before{};
  long published = 0;
  for (long n = 0;; ++n) {
    const auto when = start + std::chrono::duration_cast<Clock::duration>(step * n);
    if (when >= end) break;
    std::this_thread::sleep_until(when);
    if (!measuring && Clock::now() >= warm) {
      fleet_before = usage(fleet);
      broker_before = usage(broker);
      measuring = true;
    }
    const int i = static_cast<int>(n % machines);
    json s = state(i, std::fmod(static_cast<double>(n / machines) * 0.001, 1.0));
    s["time"] = unix_now();
    const std::string text = s.dump();
    const std::string topic = "cncd/mill-" + std::to_string(i) + "/state";
    mosquitto_publish(pub, nullptr, topic.c_str(), static_cast<int>(text.size()), text.data(), 1,
                      true);
    if (measuring) ++published;
  }
  const auto fleet_after = usage(fleet);
  const auto broker_after = usage(broker);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  done = true;
  mosquitto_disconnect(pub);
  mosquitto_loop_stop(pub, false);
  mosquitto_destroy(pub);
  end_children();  // the reader's read ends with the page's close
  reader.join();
  std::filesystem::remove_all(dir);

  std::lock_guard lock(mutex);
  std::printf("cncd_fleet_bench: %d machines x %.1f Hz, %d s measured, push every %d ms\n",
              machines, hz, seconds, push_ms);
  std::printf("  published %ld states (%.0f/s); the page got %ld frames with %ld rows\n", published,
              static_cast<double>(published) / seconds, frames.load(), rows.load());
  std::printf("  publish -> WebSocket latency ms: p50 %.1f  p99 %.1f  max %.1f\n",
              percentile(latencies, 0.5), percentile(latencies, 0.99),
              latencies.empty() ? 0.0 : *std::max_element(latencies.begin(), latencies.end()));
  std::printf("  cncd-fleet CPU %.1f %% of one core, RSS %ld KiB\n",
              100 * (fleet_after.first - fleet_before.first) / seconds, fleet_after.second);
  std::printf("  mosquitto  CPU %.1f %% of one core, RSS %ld KiB\n",
              100 * (broker_after.first - broker_before.first) / seconds, broker_after.second);
  return 0;
}
