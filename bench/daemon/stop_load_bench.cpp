// Stop round trips under hostile load: the time from sending jog.stop or machine.estop, while
// the machine jogs, to its answer, and whether the machine then came to rest. Three loads, one
// after the other, on one daemon running config/examples/sim_mm.ini:
//   flood      64 read-only clients, each keeping two batches of 256 status.get in flight
//   subscribe  300 read-only clients subscribed to the whole status every 10 ms
//   open       a control client opening a program of LINES lines over and over
//   stalled-broker  cncd-telemetry publishing to an MQTT "broker" that takes the connection
//              and never answers
// The read-only clients run in a child process as uid nobody in the group "users", made the
// daemon's READ_GROUP; without root (or that group) they run as the bench's own user, which
// has control access, and the table says so. Each row also counts the servo overruns during its
// tries. Prints figures; never fails on timing.
//
//   cncd_stop_load_bench [TRIES=200] [LINES=10000000]
//                        [LOADS=flood,subscribe,open,stalled-broker]
#include <arpa/inet.h>
#include <grp.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/wait.h>

#include <fstream>
#include <sstream>

#include "bench_client.hpp"

namespace {

using namespace cncd::bench;

constexpr uid_t kNobody = 65534;

// Killed on every way out, so that no daemon or load outlives the bench.
pid_t daemon_pid = -1;
pid_t load_pid = -1;
void end_children() {
  for (const pid_t pid : {load_pid, daemon_pid}) {
    if (pid > 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
}

std::string request(const char* method, const std::string& params = "") {
  return std::string(R"({"jsonrpc":"2.0","id":1,"method":")") + method + "\"" +
         (params.empty() ? "" : ",\"params\":" + params) + "}";
}

std::string answer_to(Conn& c, const std::string& line) {
  send_line(c, line);
  return read_answer(c);
}

// Round trip of one request in ms, and its answer.
double timed(Conn& c, const std::string& line, std::string& answer) {
  const auto t0 = Clock::now();
  send_line(c, line);
  answer = read_answer(c);
  if (answer.empty()) {
    std::fprintf(stderr, "no answer from cncd within 10 s to %s\n", line.c_str());
    std::exit(1);
  }
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// True once status.get shows `expect` within 5 s.
bool reaches(Conn& c, const char* fields, const std::string& expect) {
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (Clock::now() < deadline) {
    if (answer_to(c, request("status.get", fields)).find(expect) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

bool become_reader() {
  const group* users = getgrnam("users");
  if (geteuid() != 0 || users == nullptr) return false;
  const gid_t gid = users->gr_gid;
  return setgroups(1, &gid) == 0 && setresgid(kNobody, kNobody, kNobody) == 0 &&
         setresuid(kNobody, kNobody, kNobody) == 0;
}

void flood(const std::string& sock) {
  std::string batch = "[";
  for (int i = 0; i < 256; ++i)
    batch += (i > 0 ? "," : "") + request("status.get");
  batch += "]";
  std::vector<std::thread> threads;
  for (int t = 0; t < 64; ++t) {
    threads.emplace_back([&] {
      Conn c;
      c.fd = connect_to(sock);
      send_line(c, batch);
      for (;;) {
        if (!send_line(c, batch)) return;
        if (read_answer(c, std::chrono::seconds(60)).empty()) return;
      }
    });
  }
  for (auto& t : threads)
    t.join();
}

void subscribe(const std::string& sock) {
  std::vector<Conn> subs(300);
  std::vector<pollfd> fds;
  for (auto& c : subs) {
    c.fd = connect_to(sock);
    send_line(c, request("status.subscribe", R"({"interval_ms":10})"));
    fds.push_back({c.fd, POLLIN, 0});
  }
  for (;;) {
    poll(fds.data(), fds.size(), 1000);
    for (std::size_t i = 0; i < subs.size(); ++i) {
      if (fds[i].revents & POLLIN) read_lines(subs[i]);
    }
  }
}

void open_again(const std::string& sock, const std::string& program) {
  Conn c;
  c.fd = connect_to(sock);
  const std::string open = request("program.open", "{\"path\":\"" + program + "\"}");
  for (;;) {
    // Refused at once while the machine moves: again a little later.
    if (answer_to(c, open).find("\"result\"") == std::string::npos)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

// A loopback port that takes connections and never answers: nobody accepts, the kernel
// completes the TCP handshake. Its socket stays open (and is inherited) for the whole run.
int silent_port() {
  const int silent = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof addr;
  if (bind(silent, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      listen(silent, 16) != 0 ||
      getsockname(silent, reinterpret_cast<sockaddr*>(&addr), &size) != 0)
    return -1;
  return ntohs(addr.sin_port);
}

// cncd-telemetry, as this process, publishing to the broker `ini` names.
void telemetry(const std::string& sock, const std::string& ini) {
  std::vector<std::string> args{
      CNCD_TELEMETRY_BINARY, "--ini",         ini,          "--socket", sock, "--metrics-listen",
      "127.0.0.1:0",         "--shdr-listen", "127.0.0.1:0"};
  std::vector<char*> argv;
  for (auto& arg : args)
    argv.push_back(arg.data());
  argv.push_back(nullptr);
  execv(argv[0], argv.data());
  _exit(127);
}

struct Row {
  std::string load;
  std::vector<double> jog_stop_ms;
  std::vector<double> estop_ms;
  int not_stopped = 0;
  long overruns = 0;
  long clients = 0;
};

// A number of status.get's answer: `key` is `"overruns":` (in rt) or `"clients":`.
long status_number(Conn& c, const std::string& key) {
  const std::string answer = answer_to(c, request("status.get", R"({"fields":["rt","clients"]})"));
  const auto at = answer.find(key);
  return at == std::string::npos ? -1 : std::atol(answer.c_str() + at + key.size());
}
long overruns(Conn& c) {
  return status_number(c, "\"overruns\":");
}

// Each try: jog X, stop the jog and wait for rest; jog again, estop, check the machine is in
// estop and at rest.
Row run_tries(Conn& control, const std::string& load, int tries) {
  Row row{load, {}, {}, 0, 0, status_number(control, "\"clients\":")};
  std::string answer;
  const long overruns_before = overruns(control);
  for (int i = 0; i < tries; ++i) {
    const std::string velocity = i % 2 == 0 ? "20" : "-20";
    const std::string jog = request("jog.start", "{\"axis\":\"X\",\"velocity\":" + velocity + "}");
    timed(control, request("machine.reset"), answer);
    timed(control, request("machine.on"), answer);
    timed(control, jog, answer);
    std::this_thread::sleep_for(std::chrono::milliseconds(5 + i % 7));
    row.jog_stop_ms.push_back(timed(control, request("jog.stop", R"({"axis":"X"})"), answer));
    if (answer.find("\"result\"") == std::string::npos ||
        !reaches(control, R"({"fields":["motion"]})", "\"idle\""))
      ++row.not_stopped;
    timed(control, jog, answer);
    std::this_thread::sleep_for(std::chrono::milliseconds(5 + i % 5));
    row.estop_ms.push_back(timed(control, request("machine.estop"), answer));
    if (answer.find("\"result\"") == std::string::npos ||
        !reaches(control, R"({"fields":["state","motion"]})", R"("motion":"idle","state":"estop")"))
      ++row.not_stopped;
  }
  row.overruns = overruns(control) - overruns_before;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  const int tries = argc > 1 ? std::atoi(argv[1]) : 200;
  const long lines = argc > 2 ? std::atol(argv[2]) : 10'000'000;
  const std::string loads = argc > 3 ? argv[3] : "flood,subscribe,open,stalled-broker";
  namespace fs = std::filesystem;
  const fs::path dir = bench_dir({".var", ".tbl"});
  fs::permissions(dir, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                           fs::perms::others_read | fs::perms::others_exec);
  // Programs open from the bench's own directory; the group "users" may read.
  std::stringstream text;
  text << std::ifstream(fs::path(CNCD_SOURCE_DIR) / "config/examples/sim_mm.ini").rdbuf();
  std::string ini = text.str();
  if (const auto at = ini.find("\nPROGRAM_PREFIX = "); at != std::string::npos)
    ini.replace(at + 1, ini.find('\n', at + 1) - at - 1, "PROGRAM_PREFIX = .");
  ini.insert(ini.find("[CNCD]\n") + 7, "READ_GROUP = users\n");
  std::ofstream(dir / "sim_mm.ini") << ini;
  const fs::path program = dir / "big.ngc";
  if (loads.find("open") != std::string::npos) write_program(program, lines);
  if (loads.find("stalled-broker") != std::string::npos) {
    std::ofstream(dir / "telemetry.ini")
        << ini
        << "\n[TELEMETRY]\nMACHINE_ID = bench\nMQTT_HOST = 127.0.0.1\nMQTT_PORT = " << silent_port()
        << "\n";
  }
  const std::string sock = (dir / "cncd.sock").string();
  daemon_pid = start_cncd(dir, sock, {"--state-dir", dir.string(), "--log-level", "warn"});
  std::atexit(end_children);
  Conn control = connect_when_up(sock);
  std::vector<Row> rows;
  rows.push_back(run_tries(control, "none", tries));
  bool readers_read_only = true;
  std::stringstream list(loads);
  for (std::string load; std::getline(list, load, ',');) {
    int ready[2];
    if (pipe(ready) != 0) return 1;
    load_pid = fork();
    if (load_pid == 0) {
      close(ready[0]);
      const char ok = load == "open" || become_reader() ? 'r' : 'c';
      [[maybe_unused]] auto n = write(ready[1], &ok, 1);
      if (load == "flood") flood(sock);
      if (load == "subscribe") subscribe(sock);
      if (load == "open") open_again(sock, program.string());
      if (load == "stalled-broker") telemetry(sock, (dir / "telemetry.ini").string());
      _exit(0);
    }
    close(ready[1]);
    char ok = 'c';
    [[maybe_unused]] auto n = read(ready[0], &ok, 1);
    close(ready[0]);
    readers_read_only = readers_read_only && ok == 'r';
    std::this_thread::sleep_for(std::chrono::seconds(2));  // the load is up
    rows.push_back(run_tries(control, load, tries));
    kill(load_pid, SIGKILL);
    waitpid(load_pid, nullptr, 0);
    load_pid = -1;
  }
  kill(daemon_pid, SIGTERM);
  waitpid(daemon_pid, nullptr, 0);
  daemon_pid = -1;
  fs::remove_all(dir);

  std::printf("tries=%d per load; program %ld lines; readers %s\n", tries, lines,
              readers_read_only ? "read-only (uid nobody, group users)"
                                : "run as this user (control access): not root or no group users");
  std::printf("%-14s %12s %12s %12s %12s %12s %9s %14s\n", "load", "jog.stop p50", "jog.stop p99",
              "estop p50", "estop p99", "not stopped", "overruns", "estop p99/none");
  const double reference = percentile(rows.front().estop_ms, 0.99);
  for (const auto& row : rows) {
    std::printf("%-14s %9.2f ms %9.2f ms %9.2f ms %9.2f ms %12d %9ld %8ld %14.2f\n",
                row.load.c_str(), percentile(row.jog_stop_ms, 0.5),
                percentile(row.jog_stop_ms, 0.99), percentile(row.estop_ms, 0.5),
                percentile(row.estop_ms, 0.99), row.not_stopped, row.overruns, row.clients,
                percentile(row.estop_ms, 0.99) / reference);
  }
  return 0;
}
