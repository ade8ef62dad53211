// cncd: the machine controller daemon.
#include <signal.h>
#include <sys/signalfd.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "cncd/config/ini_file.hpp"
#include "cncd/config/machine_config.hpp"
#include "cncd/pipeline/startup_code.hpp"
#include "instance_lock.hpp"
#include "logging.hpp"
#include "methods.hpp"
#include "server.hpp"
#include "start_checks.hpp"
#include "state_files.hpp"
#include "status_json.hpp"
#include "task.hpp"
#include "version.hpp"
#include "watchdog_gate.hpp"

namespace {

constexpr int kExitUsage = 64;        // EX_USAGE
constexpr int kExitUnavailable = 69;  // EX_UNAVAILABLE
constexpr int kExitTempFail = 75;     // EX_TEMPFAIL: another daemon holds the machine

void print_usage(std::FILE* out) {
  std::fprintf(out,
               "usage: cncd --ini FILE [--socket PATH] [--state-dir DIR] [--log-level LEVEL]\n"
               "       cncd --check-config FILE [--state-dir DIR]\n"
               "       cncd --version\n"
               "\n"
               "  --ini FILE           machine configuration (LinuxCNC-style INI)\n"
               "  --socket PATH        control socket (default: [CNCD] SOCKET, else "
               "/run/cncd/cncd.sock)\n"
               "  --state-dir DIR      where the parameter, tool and position files live\n"
               "                       (default: [CNCD] STATE_DIR, else $STATE_DIRECTORY, else\n"
               "                       $XDG_STATE_HOME/cncd/<INI name>)\n"
               "  --log-level LEVEL    trace, debug, info, warn, error, critical or off\n"
               "                       (default: [CNCD] LOG_LEVEL, else info)\n"
               "  --check-config FILE  validate FILE, print a summary of the machine, exit 0;\n"
               "                       or list every problem and exit 78\n");
}

struct Options {
  std::string ini;
  std::string socket;
  std::string log_level;
  std::string state_dir;
  bool check_only = false;
};

// Returns an exit status when the process should stop right away.
std::optional<int> parse_args(int argc, char** argv, Options& options) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* name) -> std::optional<std::string> {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "cncd: %s needs a value\n", name);
        return std::nullopt;
      }
      return std::string(argv[++i]);
    };
    if (arg == "--help" || arg == "-h") {
      print_usage(stdout);
      return 0;
    }
    if (arg == "--version") {
      std::printf("cncd %s\n", cncd::kVersion);
      return 0;
    }
    std::optional<std::string> v;
    if (arg == "--ini" || arg == "--check-config") {
      if (!(v = value(arg.c_str()))) return kExitUsage;
      options.ini = *v;
      options.check_only = options.check_only || arg == "--check-config";
    } else if (arg == "--socket") {
      if (!(v = value("--socket"))) return kExitUsage;
      options.socket = *v;
    } else if (arg == "--state-dir") {
      if (!(v = value("--state-dir"))) return kExitUsage;
      options.state_dir = *v;
    } else if (arg == "--log-level") {
      if (!(v = value("--log-level"))) return kExitUsage;
      options.log_level = *v;
    } else {
      std::fprintf(stderr, "cncd: unknown argument '%s'\n", arg.c_str());
      print_usage(stderr);
      return kExitUsage;
    }
  }
  if (options.ini.empty()) {
    std::fprintf(stderr, "cncd: no machine configuration given (--ini FILE)\n");
    print_usage(stderr);
    return kExitUsage;
  }
  return std::nullopt;
}

int serve(const cncd::config::MachineConfig& config, const std::string& socket_path) {
  using namespace cncd::daemon;
  AccessPolicy policy;
  if (const auto error =
          make_access_policy(config.cncd.read_group, config.cncd.control_group, policy);
      !error.empty()) {
    spdlog::critical("{}: [CNCD]: {}", config.path.string(), error);
    return cncd::config::kExitConfig;
  }
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  // Blocked before any thread starts so that every thread inherits the mask.
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  const int signal_fd = signalfd(-1, &signals, SFD_CLOEXEC | SFD_NONBLOCK);
  if (signal_fd < 0) {
    spdlog::critical("signalfd: {}", std::strerror(errno));
    return kExitUnavailable;
  }

  // Before anything is written or driven: one daemon a state directory and a bus.
  InstanceLocks locks;
  std::string lock_message;
  switch (lock_instance(config, locks, lock_message)) {
    case LockVerdict::taken:
      break;
    case LockVerdict::busy:
      spdlog::critical("{}", lock_message);
      return kExitTempFail;
    case LockVerdict::refused:
      spdlog::critical("{}", lock_message);
      return cncd::config::kExitConfig;
  }
  for (const auto& warning : locks.warnings)
    spdlog::warn("{}", warning);
  std::vector<StateNote> notes;
  if (const auto error = prepare_state_files(config, notes); !error.empty()) {
    spdlog::critical("{}", error);
    return cncd::config::kExitConfig;
  }
  if (!config.cncd.state_dir.empty()) {
    spdlog::info("state files in {} ({})", config.cncd.state_dir.string(),
                 config.cncd.state_dir_origin);
  }
  std::string program_dirs;
  for (const auto& dir : config.program_dirs)
    program_dirs += (program_dirs.empty() ? "" : ", ") + dir.string();
  spdlog::info("programs open from {}", program_dirs.empty() ? "nowhere" : program_dirs);
  for (const auto& note : notes) {
    if (note.warning) {
      spdlog::warn("{}", note.text);
    } else {
      spdlog::info("{}", note.text);
    }
  }
  EventLog events;
  Completions completions;
  // Declared before the task, which writes to it up to its last run's end.
  std::unique_ptr<JobHistory> jobs;
  if (!config.cncd.state_dir.empty())
    jobs = std::make_unique<JobHistory>(config.cncd.state_dir / "jobs.db");
  Task task(config, events, completions);
  task.record_jobs(jobs.get());
  if (const auto error = task.load_files(); !error.empty()) {
    spdlog::critical("{}", error);
    return cncd::config::kExitConfig;
  }
  if (const auto error = task.start(); !error.empty()) {
    spdlog::critical("cannot start motion: {}", error);
    return kExitUnavailable;
  }
  // The status counts the server's connections: built on the server's thread, once it runs.
  const Server* serving_clients = nullptr;
  StatusCache status([&task, &config, &serving_clients] {
    return status_json(task.status(), config,
                       serving_clients != nullptr ? serving_clients->client_count() : 0);
  });
  RpcDispatcher dispatcher;
  JogHeartbeats heartbeats(task, events);
  register_methods(dispatcher, task, config, events, completions, heartbeats, &status);
  dispatcher.on_close(
      [&heartbeats](const Session& session) { heartbeats.closed(session.connection); });
  // A command may change what the status shows: the next status.get sees its effect.
  dispatcher.after_command([&status] { status.invalidate(); });
  dispatcher.record_to(&events);
  const ConnectionLimits limits{static_cast<std::size_t>(config.cncd.max_connections),
                                static_cast<std::size_t>(config.cncd.max_connections_per_user),
                                static_cast<std::size_t>(config.cncd.control_reserve)};
  Server server(dispatcher, policy, status, events, completions, limits);
  serving_clients = &server;
  std::string serving = socket_path;
  // Socket activation: systemd hands over the listening socket of cncd.socket.
  if (sd_listen_fds(1) == 1 &&
      sd_is_socket_unix(SD_LISTEN_FDS_START, SOCK_STREAM, 1, nullptr, 0) > 0) {
    server.adopt(SD_LISTEN_FDS_START);
    serving = "the socket handed over by systemd";
  } else if (const auto error = server.listen(socket_path); !error.empty()) {
    spdlog::critical("cannot open control socket: {}", error);
    task.shutdown();
    return kExitUnavailable;
  }
  spdlog::info("cncd {} serving {} on {} (servo period {} ns)", cncd::kVersion,
               config.path.string(), serving, config.servo_period_ns);
  spdlog::info("at most {} connections, {} of them kept for control, {} per user",
               server.limits().total, server.limits().control_reserve, server.limits().per_user);
  sd_notify(0, "READY=1\nSTATUS=ready");

  // Fed only while the servo heartbeat advances (watchdog_gate.hpp).
  std::uint64_t watchdog_usec = 0;
  const bool watchdog = sd_watchdog_enabled(0, &watchdog_usec) > 0;
  WatchdogGate watchdog_gate(std::chrono::microseconds(watchdog_usec / 2),
                             std::chrono::steady_clock::now(), task.servo_heartbeat());
  std::string last_summary;
  for (;;) {
    // A jog's heartbeat falls due between turns too: the wait ends in time to stop it.
    int timeout_ms = task.busy() ? 2 : 50;
    if (const int due = heartbeats.ms_until_due(std::chrono::steady_clock::now()); due >= 0)
      timeout_ms = std::min(timeout_ms, due);
    server.poll_once(timeout_ms, signal_fd);
    const auto now = std::chrono::steady_clock::now();
    heartbeats.expire(now);
    if (watchdog && watchdog_gate.feed(now, task.servo_heartbeat())) sd_notify(0, "WATCHDOG=1");
    if (std::string summary = task.summary(); summary != last_summary) {
      sd_notifyf(0, "STATUS=%s", summary.c_str());
      last_summary = std::move(summary);
    }
    signalfd_siginfo info{};
    if (read(signal_fd, &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
      if (info.ssi_signo == SIGHUP) {
        spdlog::info("SIGHUP ignored: restart the service to load a new configuration");
        continue;
      }
      spdlog::info("signal {} received: stopping", info.ssi_signo);
      break;
    }
    task.poll();
  }
  sd_notify(0, "STOPPING=1");
  task.shutdown();
  server.flush_answers();
  server.close();
  close(signal_fd);
  spdlog::info("cncd stopped");
  return 0;
}

// Lists the problems and returns the exit status for an invalid configuration.
int refuse(const std::vector<cncd::config::Problem>& problems, const std::string& ini) {
  for (const auto& problem : problems) {
    std::fprintf(stderr, "%s\n", problem.to_string().c_str());
  }
  std::fprintf(stderr, "cncd: %zu problem%s in %s\n", problems.size(),
               problems.size() == 1 ? "" : "s", ini.c_str());
  return cncd::config::kExitConfig;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const auto status = parse_args(argc, argv, options)) return *status;

  cncd::config::LoadOptions load_options;
  load_options.state_dir = options.state_dir;
  const auto loaded = cncd::config::load_machine_config(options.ini, load_options);
  if (!loaded.ok()) return refuse(loaded.problems, options.ini);
  const auto& config = *loaded.config;
  // A configuration that loads must also be able to run here: its start-up code and the
  // places of its state files.
  auto problems = cncd::daemon::check_state_directories(config);
  for (auto& problem : cncd::daemon::check_state_files(config))
    problems.push_back(std::move(problem));
  for (auto& problem : cncd::pipeline::check_startup_code(config))
    problems.push_back(std::move(problem));
  if (!problems.empty()) return refuse(problems, options.ini);
  if (options.check_only) {
    for (const auto& warning : loaded.warnings) {
      std::fprintf(stderr, "warning: %s\n", warning.to_string().c_str());
    }
    std::fputs(cncd::config::describe(config).c_str(), stdout);
    return 0;
  }

  const std::string level_name =
      options.log_level.empty() ? config.cncd.log_level : options.log_level;
  const auto level = cncd::daemon::parse_log_level(level_name);
  if (!level) {
    std::fprintf(stderr, "cncd: unknown log level '%s'\n", level_name.c_str());
    return kExitUsage;
  }
  cncd::daemon::init_logging(*level);
  for (const auto& warning : loaded.warnings)
    spdlog::warn("{}", warning.to_string());
  if (config.ini) {
    for (const auto* entry : config.ini->unused_entries()) {
      spdlog::debug("{}:{}: [{}] {} is not used by cncd", entry->source.file, entry->source.line,
                    entry->section, entry->key);
    }
  }
  try {
    return serve(config, options.socket.empty() ? config.cncd.socket_path : options.socket);
  } catch (const std::exception& e) {
    spdlog::critical("fatal: {}", e.what());
    return 1;
  }
}
