// cncd-telemetry: cncd's state for a shop's systems (docs/telemetry.md). A read-only client of
// cncd's control socket; serves Prometheus' /metrics, an MTConnect SHDR adapter and MQTT
// ([TELEMETRY]).
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>

#include "app.hpp"
#include "cncd/config/machine_config.hpp"
#include "logging.hpp"
#include "shdr.hpp"
#include "version.hpp"

namespace {

void usage(std::FILE* out) {
  std::fprintf(
      out,
      "usage: cncd-telemetry --ini MACHINE.ini [--socket PATH] [--metrics-listen A:P]\n"
      "                      [--log-level L]\n\n"
      "  --ini FILE              the machine's INI: [TELEMETRY], [CNCD] SOCKET\n"
      "  --socket PATH           cncd's control socket instead of [CNCD] SOCKET\n"
      "  --metrics-listen A:P    /metrics on address A, port P (0: any free port, logged)\n"
      "                          instead of [TELEMETRY] METRICS_LISTEN\n"
      "  --log-level L           trace|debug|info|warn|error|critical|off (default info)\n");
}

// "127.0.0.1:9877" or "[::1]:0" split; false when it is not that.
bool split_listen(const std::string& text, std::string& address, int& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon + 1 == text.size() || colon + 6 < text.size())
    return false;
  address = text.substr(0, colon);
  if (address.size() > 2 && address.front() == '[' && address.back() == ']')
    address = address.substr(1, address.size() - 2);
  const std::string digits = text.substr(colon + 1);
  if (digits.find_first_not_of("0123456789") != std::string::npos) return false;
  port = std::stoi(digits);
  return port <= 65535;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path ini;
  std::string socket_path;
  std::string metrics_listen;
  std::string shdr_listen;
  bool devices = false;
  std::string log_level = "info";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--ini" && has_value) {
      ini = argv[++i];
    } else if (arg == "--socket" && has_value) {
      socket_path = argv[++i];
    } else if (arg == "--metrics-listen" && has_value) {
      metrics_listen = argv[++i];
    } else if (arg == "--shdr-listen" && has_value) {
      shdr_listen = argv[++i];
    } else if (arg == "--devices-xml") {
      devices = true;
    } else if (arg == "--log-level" && has_value) {
      log_level = argv[++i];
    } else if (arg == "--help" || arg == "-h") {
      usage(stdout);
      return 0;
    } else if (arg == "--version") {
      std::printf("cncd-telemetry %s\n", cncd::kVersion);
      return 0;
    } else {
      std::fprintf(stderr, "cncd-telemetry: unknown option '%s'\n", arg.c_str());
      usage(stderr);
      return 2;
    }
  }
  if (ini.empty()) {
    std::fprintf(stderr, "cncd-telemetry: --ini is required\n");
    usage(stderr);
    return 2;
  }
  const auto level = cncd::daemon::parse_log_level(log_level);
  if (!level) {
    std::fprintf(stderr, "cncd-telemetry: unknown log level '%s'\n", log_level.c_str());
    return 2;
  }
  auto loaded = cncd::config::load_or_report(ini, "cncd-telemetry", std::cerr);
  if (!loaded) return cncd::config::kExitConfig;
  const cncd::config::MachineConfig& machine = *loaded;
  const cncd::config::TelemetryConfig& t = machine.telemetry;
  std::string metrics_address = t.metrics_address;
  int metrics_port = t.metrics_port;
  if (!metrics_listen.empty() && !split_listen(metrics_listen, metrics_address, metrics_port)) {
    std::fprintf(stderr, "cncd-telemetry: --metrics-listen needs ADDRESS:PORT, not '%s'\n",
                 metrics_listen.c_str());
    return 2;
  }
  std::string shdr_address = t.shdr_address;
  int shdr_port = t.shdr_port;
  if (!shdr_listen.empty() && !split_listen(shdr_listen, shdr_address, shdr_port)) {
    std::fprintf(stderr, "cncd-telemetry: --shdr-listen needs ADDRESS:PORT, not '%s'\n",
                 shdr_listen.c_str());
    return 2;
  }
  if (socket_path.empty()) socket_path = machine.cncd.socket_path;
  std::vector<char> axes;
  for (std::size_t i = 0; i < cncd::config::kAxisLetters.size(); ++i) {
    if (machine.axes[i].present) axes.push_back(cncd::config::kAxisLetters[i]);
  }
  if (devices) {
    std::fputs(cncd::telemetry::devices_xml(t.machine_id, machine.machine_name, axes).c_str(),
               stdout);
    return 0;
  }

  cncd::daemon::init_logging(*level);
  boost::asio::io_context io;
  cncd::telemetry::App app(io, t, socket_path, axes);
  cncd::telemetry::Endpoints endpoints{metrics_address, metrics_port, !metrics_listen.empty(),
                                       shdr_address,    shdr_port,    !shdr_listen.empty()};
  if (const auto error = app.start(endpoints); !error.empty()) {
    spdlog::critical("{}", error);
    return 1;
  }
  spdlog::info("cncd-telemetry {} for machine '{}', cncd at {}", cncd::kVersion, t.machine_id,
               socket_path);
  boost::asio::signal_set signals(io, SIGTERM, SIGINT);
  signals.async_wait([&](const boost::system::error_code& ec, int signal) {
    if (ec) return;
    spdlog::info("signal {}: shutting down", signal);
    app.stop();
    io.stop();
  });
  io.run();
  spdlog::info("cncd-telemetry stopped");
  return 0;
}
