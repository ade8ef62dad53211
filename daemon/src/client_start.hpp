// The start of the programs that serve others from cncd's control socket (cncd-web,
// cncd-telemetry): the options they all take and the machine's INI, read before anything runs,
// and the loop that serves until a signal.
#pragma once

#include <chrono>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>

#include <spdlog/common.h>
#include <boost/asio/io_context.hpp>

#include "cncd/config/machine_config.hpp"

namespace cncd::daemon {

struct ClientStart {
  std::optional<int> exit_status;  // set: exit with it now (help, version, bad usage or INI)
  std::optional<config::MachineConfig> machine;
  std::string socket_path;  // --socket; empty: [CNCD] SOCKET
  spdlog::level::level_enum log_level = spdlog::level::info;
};

// A program's own option: `arg` and the argument after it (nullptr after the last); returns
// how many arguments it takes, 0 for one it does not know.
using ClientOption = std::function<int(const std::string& arg, const char* next)>;

// Reads --ini FILE (required), --socket PATH, --log-level L, --help / -h and --version, hands
// every other argument to `own`, then loads the INI and writes its problems to stderr. Usage
// errors exit 2 after `usage(stderr)`, a bad INI exits config::kExitConfig.
ClientStart start_client(int argc, char** argv, const char* program, void (*usage)(std::FILE*),
                         const ClientOption& own);

// Runs `io` until SIGTERM or SIGINT, which is logged and calls `stop`. With `linger` 0, `stop`
// ends the loop itself; else the loop is stopped that long after (the close frames of
// WebSockets `stop` closed go out meanwhile).
void run_until_signal(boost::asio::io_context& io, const std::function<void()>& stop,
                      std::chrono::milliseconds linger = std::chrono::milliseconds(0));

}  // namespace cncd::daemon
