// Interpreter throughput and memory, side by side with LinuxCNC's rs274 when it is installed.
// Generates into a temporary directory a G1 3D surfacing program (1,000,000 lines), a program
// of 100,000 G81 blocks and, for memory, a 10,000,000-line surfacing program. Each run is a
// child process of its own: our interpreter into a null sink (interpretation alone),
// `cncd-check --canon` (the canonical commands as text) and `rs274 -g` (its canonical text;
// its own HOME), both with their output going to /dev/null. Prints lines/s by wall-clock and
// by CPU time (user + system, which other load on the machine disturbs less), peak resident
// memory, and the ratios to rs274.
//
//   cncd_interp_bench [--scale F] [--no-rs274] [--no-memory]
//
// --scale multiplies every program's length (0.1 for a quick look). A benchmark, never a test.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"  // NullSink

namespace {

namespace fs = std::filesystem;
constexpr const char* kRs274 = "/usr/bin/rs274";
constexpr const char* kCncdCheck = CNCD_CHECK_BINARY;

// A raster over a 100 x 100 mm sine-shaped surface: each line one G1 with X, Y and Z.
void write_surfacing(const fs::path& path, long lines) {
  std::ofstream out(path);
  out << "G21 G90 G17 G94 F1500\nG0 X0 Y0 Z5\n";
  const long per_row = 1000;
  char text[96];
  for (long i = 0; i < lines; ++i) {
    const long row = i / per_row;
    const long col = row % 2 == 0 ? i % per_row : per_row - 1 - i % per_row;
    const double x = col * 0.1;
    const double y = static_cast<double>(row % 1000) * 0.1;
    const double z = -1.0 + 0.5 * std::sin(x * 0.2) * std::cos(y * 0.3);
    std::snprintf(text, sizeof text, "G1 X%.3f Y%.3f Z%.4f\n", x, y, z);
    out << text;
  }
  out << "G0 Z5\nM2\n";
}

// Drilling a 100 x 100 mm grid, one G81 block a hole, alternating R retracts (G98/G99).
void write_drilling(const fs::path& path, long blocks) {
  std::ofstream out(path);
  out << "G21 G90 G17 G94 F300\nG0 X0 Y0 Z10\n";
  char text[96];
  for (long i = 0; i < blocks; ++i) {
    std::snprintf(text, sizeof text, "%s G81 X%.3f Y%.3f Z-2.5 R1.0\n", i % 2 ? "G99" : "G98",
                  static_cast<double>(i % 500) * 0.2, static_cast<double>(i / 500 % 500) * 0.2);
    out << text;
  }
  out << "G80\nG0 Z10\nM2\n";
}

long count_lines(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  long lines = 0;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i)
      lines += buffer[i] == '\n';
  }
  return lines;
}

struct Run {
  bool ok = false;
  double seconds = 0;      // wall clock
  double cpu_seconds = 0;  // the child's user + system time
  long peak_rss_kb = 0;    // the child's ru_maxrss
};

double seconds_of(const timeval& t) {
  return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
}

// Runs `child` in a forked process; its exit status 0 means success. Times the whole child.
template <typename Child>
Run in_child(Child child) {
  std::fflush(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) return {};
  if (pid == 0) _exit(child());
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) return {};
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  Run run;
  run.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  run.seconds = elapsed.count();
  run.cpu_seconds = seconds_of(usage.ru_utime) + seconds_of(usage.ru_stime);
  run.peak_rss_kb = usage.ru_maxrss;
  return run;
}

Run run_ours(const fs::path& program) {
  return in_child([&program] {
    cncd::interp::Interpreter interp;
    cncd::interp::NullSink sink;
    auto error = interp.open(program);
    if (!error) error = cncd::interp::run_program(interp, sink);
    if (error) std::fprintf(stderr, "%s\n", error->to_string().c_str());
    return error ? 1 : 0;
  });
}

// Runs `binary -g|--canon program` with its output thrown away, in `home` (rs274 keeps its tool
// data in a file there): the same invocation as the differential test.
Run run_canon_text(const char* binary, const char* option, const fs::path& program,
                   const fs::path& home) {
  return in_child([&] {
    if (!freopen("/dev/null", "r", stdin) || !freopen("/dev/null", "w", stdout) ||
        !freopen("/dev/null", "w", stderr) || setenv("HOME", home.c_str(), 1) != 0 ||
        chdir(home.c_str()) != 0) {
      return 1;
    }
    execl(binary, binary, option, program.c_str(), static_cast<char*>(nullptr));
    return 127;
  });
}

// One row: wall seconds, lines/s by wall clock, CPU seconds, lines/s by CPU time, peak RSS.
void print_row(const char* what, const Run& run, long lines) {
  if (!run.ok) {
    std::printf("  %-34s FAILED\n", what);
    return;
  }
  std::printf("  %-34s %7.2f %13.0f %7.2f %13.0f %13ld\n", what, run.seconds,
              static_cast<double>(lines) / run.seconds, run.cpu_seconds,
              static_cast<double>(lines) / run.cpu_seconds, run.peak_rss_kb);
}

// Our lines/s over rs274's.
void print_ratio(const char* what, const Run& ours, const Run& theirs) {
  if (!ours.ok || !theirs.ok) return;
  std::printf("  %-34s %6.1fx by wall clock, %6.1fx by CPU time\n", what,
              theirs.seconds / ours.seconds, theirs.cpu_seconds / ours.cpu_seconds);
}

// `text` adds the runs that print canonical commands: cncd-check --canon and, with `with_rs274`,
// rs274 -g.
void report(const char* name, const fs::path& program, bool text, bool with_rs274,
            const fs::path& home) {
  const long lines = count_lines(program);
  const std::string title = std::string(name) + ", " + std::to_string(lines) + " lines";
  std::printf("%-36s %7s %13s %7s %13s %13s\n", title.c_str(), "wall s", "wall lines/s", "CPU s",
              "CPU lines/s", "peak RSS KiB");
  const Run interpretation = run_ours(program);
  print_row("cncd interpretation alone", interpretation, lines);
  if (!text) return;
  const bool with_check = fs::exists(kCncdCheck);
  Run canon;
  if (with_check) {
    canon = run_canon_text(kCncdCheck, "--canon", program, home);
    print_row("cncd canon text (cncd-check)", canon, lines);
  } else {
    std::printf("  cncd-check --canon not run (%s not built)\n", kCncdCheck);
  }
  if (!with_rs274) return;
  const Run theirs = run_canon_text(kRs274, "-g", program, home);
  print_row("rs274 -g canon text", theirs, lines);
  if (!theirs.ok) return;
  print_ratio("cncd/rs274 interpretation alone", interpretation, theirs);
  if (with_check) print_ratio("cncd/rs274 canon text", canon, theirs);
}

}  // namespace

int main(int argc, char** argv) {
  double scale = 1.0;
  bool rs274 = fs::exists(kRs274);
  bool memory = true;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--scale" && i + 1 < argc) {
      scale = std::atof(argv[++i]);
    } else if (arg == "--no-rs274") {
      rs274 = false;
    } else if (arg == "--no-memory") {
      memory = false;
    } else {
      std::fprintf(stderr, "usage: cncd_interp_bench [--scale F] [--no-rs274] [--no-memory]\n");
      return 2;
    }
  }
  if (!(scale > 0)) {
    std::fprintf(stderr, "cncd_interp_bench: --scale must be positive\n");
    return 2;
  }
  char pattern[] = "/tmp/cncd-interp-bench-XXXXXX";
  if (!mkdtemp(pattern)) {
    std::perror("mkdtemp");
    return 1;
  }
  const fs::path dir = pattern;
  const fs::path home = dir / "home";
  fs::create_directories(home);
  if (!rs274)
    std::printf("rs274 not run (%s)\n", fs::exists(kRs274) ? "--no-rs274" : "not installed");

  const auto scaled = [scale](long n) { return std::max(1L, std::lround(n * scale)); };
  write_surfacing(dir / "surface_1m.ngc", scaled(1'000'000));
  report("G1 surfacing", dir / "surface_1m.ngc", true, rs274, home);
  write_drilling(dir / "drill_g81.ngc", scaled(100'000));
  report("G81 drilling", dir / "drill_g81.ngc", true, rs274, home);
  if (memory) {
    fs::remove(dir / "surface_1m.ngc");
    write_surfacing(dir / "surface_10m.ngc", scaled(10'000'000));
    report("G1 surfacing (memory)", dir / "surface_10m.ngc", false, false, home);
    write_surfacing(dir / "surface_10.ngc", 10);
    report("G1 surfacing (short)", dir / "surface_10.ngc", false, false, home);
  }
  fs::remove_all(dir);
  return 0;
}
