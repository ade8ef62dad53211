// cncd-drive-sim: simulated Modbus servo drives for trying cncd's modbus driver without
// hardware. SIGUSR1 toggles a drive fault on every drive, SIGUSR2 toggles "silent" (requests
// time out); SIGINT/SIGTERM stop it.
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "cncd/drivers/drive_sim.hpp"

namespace {

volatile sig_atomic_t g_stop = 0;
volatile sig_atomic_t g_fault_toggles = 0;
volatile sig_atomic_t g_silent_toggles = 0;

void on_signal(int signal) {
  if (signal == SIGUSR1) {
    g_fault_toggles = g_fault_toggles + 1;
  } else if (signal == SIGUSR2) {
    g_silent_toggles = g_silent_toggles + 1;
  } else {
    g_stop = 1;
  }
}

void usage() {
  std::puts(
      "usage: cncd-drive-sim [--port N] [--address A] [--rtu] [--drives N] [--slave ID]\n"
      "                      [--lag SECONDS] [--fault-after SECONDS] [--exception]\n"
      "                      [--rt-priority N]\n"
      "  --port N          Modbus TCP port (default 1502; 0 = any free port, printed)\n"
      "  --address A       address to listen on (default 127.0.0.1)\n"
      "  --rtu             serve Modbus RTU on a new pseudo-terminal (its path is printed)\n"
      "  --drives N        drives with unit ids ID .. ID+N-1 (default 3; RTU: 1)\n"
      "  --slave ID        first unit id (default 1)\n"
      "  --lag SECONDS     following time constant (default 0.01)\n"
      "  --fault-after S   set the fault bit of every drive after S seconds\n"
      "  --exception       answer every request with an exception\n"
      "  --rt-priority N   serve from SCHED_FIFO threads of priority N (1-99), as a drive\n"
      "                    with a processor of its own; default 0: ordinary threads\n"
      "signals: SIGUSR1 toggles a fault on every drive, SIGUSR2 toggles silence");
}

}  // namespace

int main(int argc, char** argv) {
  cncd::drivers::DriveSimOptions options;
  options.port = 1502;
  options.drives = 3;
  double fault_after_s = -1;
  bool exception = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "cncd-drive-sim: %s needs a value\n", arg.c_str());
        std::exit(64);
      }
      return argv[++i];
    };
    if (arg == "--port") {
      options.port = std::atoi(value());
    } else if (arg == "--address") {
      options.address = value();
    } else if (arg == "--rtu") {
      options.rtu = true;
    } else if (arg == "--drives") {
      options.drives = std::atoi(value());
    } else if (arg == "--slave") {
      options.first_slave = std::atoi(value());
    } else if (arg == "--lag") {
      options.lag_s = std::atof(value());
    } else if (arg == "--fault-after") {
      fault_after_s = std::atof(value());
    } else if (arg == "--rt-priority") {
      const char* text = value();
      char* end = nullptr;
      const long priority = std::strtol(text, &end, 10);
      if (end == text || *end != '\0' || priority < 0 || priority > 99) {
        std::fprintf(stderr, "cncd-drive-sim: --rt-priority wants 0 to 99, not '%s'\n", text);
        return 64;
      }
      options.rt_priority = static_cast<int>(priority);
    } else if (arg == "--exception") {
      exception = true;
    } else if (arg == "--help" || arg == "-h") {
      usage();
      return 0;
    } else {
      std::fprintf(stderr, "cncd-drive-sim: unknown option %s\n", arg.c_str());
      usage();
      return 64;
    }
  }
  if (options.rtu) options.drives = 1;
  struct sigaction action {};
  action.sa_handler = on_signal;
  for (const int s : {SIGINT, SIGTERM, SIGUSR1, SIGUSR2})
    sigaction(s, &action, nullptr);
  cncd::drivers::DriveSim sim(options);
  if (const auto error = sim.start(); !error.empty()) {
    std::fprintf(stderr, "cncd-drive-sim: %s\n", error.c_str());
    return 69;
  }
  if (options.rtu) {
    std::printf("cncd-drive-sim: RTU unit %d on %s\n", options.first_slave, sim.device().c_str());
  } else {
    std::printf("cncd-drive-sim: %d drive(s), unit ids %d..%d, on %s:%d\n", options.drives,
                options.first_slave, options.first_slave + options.drives - 1,
                options.address.c_str(), sim.port());
  }
  std::fflush(stdout);
  if (const auto warning = sim.warning(); !warning.empty())
    std::fprintf(stderr, "cncd-drive-sim: warning: %s\n", warning.c_str());
  sim.set_exception(exception);
  int faults_seen = 0;
  int silences_seen = 0;
  bool faulted = false;
  bool silent = false;
  for (long ms = 0; g_stop == 0; ms += 10) {
    usleep(10'000);
    const bool timed_fault = fault_after_s >= 0 && static_cast<double>(ms) >= fault_after_s * 1000;
    if (g_fault_toggles != faults_seen || (timed_fault && !faulted && fault_after_s >= 0)) {
      faults_seen = g_fault_toggles;
      faulted = !faulted;
      if (timed_fault) fault_after_s = -1;
      for (int id = options.first_slave; id < options.first_slave + options.drives; ++id)
        sim.set_fault(id, faulted);
      std::printf("cncd-drive-sim: fault %s\n", faulted ? "set" : "cleared");
      std::fflush(stdout);
    }
    if (g_silent_toggles != silences_seen) {
      silences_seen = g_silent_toggles;
      silent = !silent;
      sim.set_silent(silent);
      std::printf("cncd-drive-sim: %s\n", silent ? "silent" : "answering");
      std::fflush(stdout);
    }
  }
  sim.stop();
  return 0;
}
