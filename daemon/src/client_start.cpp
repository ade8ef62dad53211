#include "client_start.hpp"

#include <csignal>
#include <filesystem>
#include <iostream>

#include <spdlog/spdlog.h>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include "logging.hpp"
#include "version.hpp"

namespace cncd::daemon {

ClientStart start_client(int argc, char** argv, const char* program, void (*usage)(std::FILE*),
                         const ClientOption& own) {
  ClientStart out;
  std::filesystem::path ini;
  std::string log_level = "info";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--ini" && has_value) {
      ini = argv[++i];
    } else if (arg == "--socket" && has_value) {
      out.socket_path = argv[++i];
    } else if (arg == "--log-level" && has_value) {
      log_level = argv[++i];
    } else if (arg == "--help" || arg == "-h") {
      usage(stdout);
      out.exit_status = 0;
      return out;
    } else if (arg == "--version") {
      std::printf("%s %s\n", program, kVersion);
      out.exit_status = 0;
      return out;
    } else if (const int taken = own(arg, has_value ? argv[i + 1] : nullptr); taken > 0) {
      i += taken - 1;
    } else {
      std::fprintf(stderr, "%s: unknown option '%s'\n", program, arg.c_str());
      usage(stderr);
      out.exit_status = 2;
      return out;
    }
  }
  if (ini.empty()) {
    std::fprintf(stderr, "%s: --ini is required\n", program);
    usage(stderr);
    out.exit_status = 2;
    return out;
  }
  const auto level = parse_log_level(log_level);
  if (!level) {
    std::fprintf(stderr, "%s: unknown log level '%s'\n", program, log_level.c_str());
    out.exit_status = 2;
    return out;
  }
  out.log_level = *level;
  out.machine = config::load_or_report(ini, program, std::cerr);
  if (!out.machine) out.exit_status = config::kExitConfig;
  return out;
}

void run_until_signal(boost::asio::io_context& io, const std::function<void()>& stop,
                      std::chrono::milliseconds linger) {
  boost::asio::signal_set signals(io, SIGTERM, SIGINT);
  boost::asio::steady_timer last(io);
  signals.async_wait([&](const boost::system::error_code& ec, int signal) {
    if (ec) return;
    spdlog::info("signal {}: shutting down", signal);
    stop();
    if (linger.count() == 0) return;
    last.expires_after(linger);
    last.async_wait([&io](const boost::system::error_code&) { io.stop(); });
  });
  io.run();
}

}  // namespace cncd::daemon
