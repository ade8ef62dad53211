// program.preview of a large 3D program: a surface of LINES feed moves 0.15 mm apart (as 3D
// finishing writes them) opened on the sim machine, then previewed at the default tolerance
// and at a fine one. Prints how long the open and each preview take, the answer's size and
// points, the status round trips of another client while the preview is worked out, and
// whether the extents equal `cncd-check --preview`'s. Prints figures; never fails on timing.
//
//   cncd_preview_bench [LINES=1000000] [FINE_TOLERANCE=0.0005]
#include <signal.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench_client.hpp"

namespace {

using namespace cncd::bench;

pid_t daemon_pid = -1;
void end_daemon() {
  if (daemon_pid > 0) {
    kill(daemon_pid, SIGKILL);
    waitpid(daemon_pid, nullptr, 0);
  }
}

void write_surface(const std::filesystem::path& path, long lines) {
  std::ofstream out(path);
  out << "G21 G90 G94 G64 P0.01\nG0 Z5\nG0 X0 Y0\nG1 Z0 F1000\n";
  const long columns = 1000;
  char line[96];
  for (long i = 0; i < lines; ++i) {
    const long r = i / columns;
    const long c = r % 2 == 0 ? i % columns : columns - 1 - i % columns;
    const double x = static_cast<double>(c) * 0.15;
    const double y = static_cast<double>(r) * 0.15;
    std::snprintf(line, sizeof line, "X%.4f Y%.4f Z%.4f\n", x, y,
                  -3 + 2 * std::sin(x / 12) * std::cos(y / 9) + 0.5 * std::sin((x + y) / 5));
    out << line;
  }
  out << "G0 Z5\nM2\n";
}

std::string request(const std::string& method, const std::string& params = "") {
  return R"({"jsonrpc":"2.0","id":1,"method":")" + method + "\"" +
         (params.empty() ? "" : ",\"params\":" + params) + "}";
}

struct Timed {
  double ms = 0;
  std::string answer;
};

Timed timed(Conn& c, const std::string& line, std::chrono::seconds limit) {
  const auto t0 = Clock::now();
  send_line(c, line);
  Timed out;
  out.answer = read_answer(c, limit);
  out.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  if (out.answer.empty()) {
    std::fprintf(stderr, "no answer to %s\n", line.c_str());
    std::exit(1);
  }
  return out;
}

// Previews at `tolerance` while another connection asks for status every 10 ms; prints a row.
nlohmann::json preview(const std::string& sock, const std::string& tolerance, const char* label) {
  Conn asker = connect_when_up(sock);
  Conn other = connect_when_up(sock);
  const auto t0 = Clock::now();
  send_line(asker, request("program.preview", "{\"tolerance\":" + tolerance + "}"));
  std::vector<double> round_trips;
  std::string answer;
  while (answer.empty()) {
    round_trips.push_back(timed(other, request("status.get"), std::chrono::seconds(10)).ms);
    for (auto& line : read_lines(asker)) {
      if (line.find("\"id\"") != std::string::npos) answer = std::move(line);
    }
    if (answer.empty()) {
      pollfd p{asker.fd, POLLIN, 0};
      poll(&p, 1, 10);
    }
    if (Clock::now() - t0 > std::chrono::minutes(5)) {
      std::fprintf(stderr, "no preview within 5 min\n");
      std::exit(1);
    }
  }
  const double first_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  const double again_ms =
      timed(asker, request("program.preview", "{\"tolerance\":" + tolerance + "}"),
            std::chrono::seconds(60))
          .ms;
  const auto json = nlohmann::json::parse(answer);
  if (!json.contains("result")) {
    std::fprintf(stderr, "preview refused: %s\n", answer.substr(0, 400).c_str());
    std::exit(1);
  }
  const auto& r = json["result"];
  std::printf("%-9s %10s %9.0f ms %9.1f ms %9.2f MB %9d %9d %11.5f %8.2f / %.2f ms\n", label,
              tolerance.c_str(), first_ms, again_ms, static_cast<double>(answer.size()) / 1e6,
              r["source_points"].get<int>(), r["points"].get<int>(), r["tolerance"].get<double>(),
              percentile(round_trips, 0.5), percentile(round_trips, 0.99));
  close(asker.fd);
  close(other.fd);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const long lines = argc > 1 ? std::atol(argv[1]) : 1'000'000;
  const std::string fine = argc > 2 ? argv[2] : "0.0005";
  namespace fs = std::filesystem;
  const fs::path dir = bench_dir({".var", ".tbl"});
  std::stringstream text;
  text << std::ifstream(fs::path(CNCD_SOURCE_DIR) / "config/examples/sim_mm.ini").rdbuf();
  std::string ini = text.str();
  if (const auto at = ini.find("\nPROGRAM_PREFIX = "); at != std::string::npos)
    ini.replace(at + 1, ini.find('\n', at + 1) - at - 1, "PROGRAM_PREFIX = .");
  std::ofstream(dir / "sim_mm.ini") << ini;
  const fs::path program = dir / "surface.ngc";
  write_surface(program, lines);
  const std::string sock = (dir / "cncd.sock").string();
  daemon_pid = start_cncd(dir, sock, {"--state-dir", dir.string(), "--log-level", "warn"});
  std::atexit(end_daemon);
  Conn control = connect_when_up(sock);
  const Timed open =
      timed(control, request("program.open", "{\"path\":\"" + program.string() + "\"}"),
            std::chrono::seconds(300));
  if (open.answer.find("\"result\"") == std::string::npos) {
    std::fprintf(stderr, "open failed: %s\n", open.answer.c_str());
    return 1;
  }
  std::printf("program: %ld lines, %.1f MB; program.open %.0f ms\n", lines + 6,
              static_cast<double>(fs::file_size(program)) / 1e6, open.ms);
  std::printf("%-9s %10s %12s %12s %12s %9s %9s %11s %s\n", "preview", "tolerance", "first", "kept",
              "answer", "source", "points", "reached", "status.get p50 / p99 meanwhile");
  const auto coarse = preview(sock, "0.01", "default");
  preview(sock, fine, "fine");
  // The extents of cncd-check --preview on the same program, INI and state files.
  const std::string command = std::string(CNCD_CHECK_BINARY) + " --preview --ini " +
                              (dir / "sim_mm.ini").string() + " --state-dir " + dir.string() + " " +
                              program.string();
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char chunk[65536];
    std::size_t n;
    while ((n = fread(chunk, 1, sizeof chunk, pipe)) > 0)
      out.append(chunk, n);
    pclose(pipe);
  }
  const auto check = nlohmann::json::parse(out, nullptr, false);
  const bool equal = !check.is_discarded() && check["extents"] == coarse["extents"];
  std::printf("extents %s; cncd-check's %s\n", coarse["extents"].dump().c_str(),
              equal
                  ? "equal"
                  : ("DIFFER: " + (check.is_discarded() ? out : check["extents"].dump())).c_str());
  kill(daemon_pid, SIGTERM);
  waitpid(daemon_pid, nullptr, 0);
  daemon_pid = -1;
  fs::remove_all(dir);
  return 0;
}
