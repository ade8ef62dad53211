// cncd-telemetry: cncd's state for a shop's systems (docs/telemetry.md). A read-only client of
// cncd's control socket; serves Prometheus' /metrics, an MTConnect SHDR adapter and MQTT
// ([TELEMETRY]).
#include <cstdio>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "app.hpp"
#include "client_start.hpp"
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

// An ADDRESS:PORT option given over the INI's address and port; false, said, when it is not
// that.
bool listen_option(const char* option, const std::string& text, std::string& address, int& port) {
  if (text.empty() || split_listen(text, address, port)) return true;
  std::fprintf(stderr, "cncd-telemetry: %s needs ADDRESS:PORT, not '%s'\n", option, text.c_str());
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  std::string metrics_listen;
  std::string shdr_listen;
  bool devices = false;
  auto start = cncd::daemon::start_client(argc, argv, "cncd-telemetry", usage,
                                          [&](const std::string& arg, const char* next) {
                                            if (arg == "--metrics-listen" && next != nullptr) {
                                              metrics_listen = next;
                                              return 2;
                                            }
                                            if (arg == "--shdr-listen" && next != nullptr) {
                                              shdr_listen = next;
                                              return 2;
                                            }
                                            if (arg == "--devices-xml") {
                                              devices = true;
                                              return 1;
                                            }
                                            return 0;
                                          });
  if (start.exit_status) return *start.exit_status;
  const cncd::config::MachineConfig& machine = *start.machine;
  const cncd::config::TelemetryConfig& t = machine.telemetry;
  std::string metrics_address = t.metrics_address;
  int metrics_port = t.metrics_port;
  std::string shdr_address = t.shdr_address;
  int shdr_port = t.shdr_port;
  if (!listen_option("--metrics-listen", metrics_listen, metrics_address, metrics_port) ||
      !listen_option("--shdr-listen", shdr_listen, shdr_address, shdr_port))
    return 2;
  std::string socket_path = start.socket_path;
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

  cncd::daemon::init_logging(start.log_level);
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
  cncd::daemon::run_until_signal(io, [&] {
    app.stop();
    io.stop();
  });
  spdlog::info("cncd-telemetry stopped");
  return 0;
}
