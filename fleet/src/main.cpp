// cncd-fleet: every machine that publishes to an MQTT broker on one page (docs/fleet.md). It
// reads the broker only (the state, availability and events cncd-telemetry publishes); it
// never talks to a machine.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "accept_loop.hpp"
#include "client_start.hpp"
#include "fleet_app.hpp"
#include "logging.hpp"
#include "sessions.hpp"
#include "subscriber.hpp"
#include "version.hpp"

namespace {

std::filesystem::path exe_dir() {
  std::error_code ec;
  return std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 1 && args[0] == "--version") {
    std::printf("cncd-fleet %s\n", cncd::kVersion);
    return 0;
  }
  auto parsed = cncd::fleet::parse_options(args);
  if (!parsed.options) {
    std::fputs(parsed.message.c_str(), parsed.status == 0 ? stdout : stderr);
    return parsed.status;
  }
  auto options = std::move(*parsed.options);
  const auto level = cncd::daemon::parse_log_level(options.log_level);
  if (!level) {
    std::fprintf(stderr, "cncd-fleet: unknown log level '%s'\n", options.log_level.c_str());
    return 2;
  }
  cncd::daemon::init_logging(*level);
  if (options.www.empty()) options.www = exe_dir() / ".." / "share" / "cncd" / "fleet-www";
  boost::asio::io_context io;
  try {
    cncd::fleet::FleetApp app(io, options);
    namespace asio = boost::asio;
    using tcp = asio::ip::tcp;
    cncd::web::AcceptLoop listener(
        io,
        tcp::endpoint(asio::ip::make_address(options.listen_address),
                      static_cast<unsigned short>(options.listen_port)),
        [&app](tcp::socket socket) {
          boost::system::error_code ec;
          const auto remote = socket.remote_endpoint(ec);
          const std::string address = ec ? "?" : remote.address().to_string();
          if (app.connections >= cncd::fleet::kMaxConnections) {
            spdlog::warn("connection from {} refused: {} connections open", address,
                         app.connections);
            return;
          }
          std::make_shared<cncd::fleet::HttpConnection>(app, std::move(socket), address)
              ->read_next();
        });
    cncd::fleet::Subscriber subscriber(
        io, options.broker, cncd::fleet::topic_filters(options.pattern), options.limits.max_payload,
        {[&app](std::string topic, std::string payload) { app.on_message(topic, payload); },
         [&app](std::string topic, std::size_t bytes) { app.on_too_large(topic, bytes); },
         [&app](bool connected) { app.on_broker(connected); }});
    if (const auto problem = subscriber.start(); !problem.empty()) {
      spdlog::critical("{}", problem);
      return 1;
    }
    listener.start();
    spdlog::info("cncd-fleet {} serving http://{}:{} for the machines under {}", cncd::kVersion,
                 options.listen_address, listener.endpoint().port(), options.pattern);
    cncd::daemon::run_until_signal(
        io,
        [&] {
          listener.stop();
          subscriber.stop();
          app.close_all("cncd-fleet is shutting down");
        },
        std::chrono::milliseconds(300));  // the WebSockets' close frames go out
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  spdlog::info("stopped");
  return 0;
}
