// cncd-web: the browser dashboard and WebSocket proxy of cncd (docs/web.md). A client of
// cncd's control socket like cncctl; serves the page, the programs API and /ws on
// [WEB] LISTEN:PORT. `cncd-web --ini INI user|key ...` manages its users instead.
#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>

#include "admin_entry.hpp"
#include "app.hpp"
#include "cncd/web/admin_cli.hpp"
#include "listener.hpp"
#include "logging.hpp"
#include "status_watch.hpp"
#include "version.hpp"

namespace {

using cncd::web::App;

void usage(std::FILE* out) {
  std::fprintf(out,
               "usage: cncd-web --ini MACHINE.ini [--socket PATH] [--www DIR] [--log-level L]\n"
               "       cncd-web --ini MACHINE.ini user|key ...   (manage the users file)\n\n"
               "  --ini FILE     the machine's INI: [WEB] for cncd-web, [CNCD] SOCKET\n"
               "  --socket PATH  cncd's control socket instead of [CNCD] SOCKET\n"
               "  --www DIR      the page's files instead of <bin>/../share/cncd/www\n"
               "  --log-level L  trace|debug|info|warn|error|critical|off (default info)\n\n%s",
               cncd::web::admin_usage().c_str());
}

std::filesystem::path exe_dir() {
  std::error_code ec;
  return std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path ini;
  std::string socket_path;
  std::filesystem::path www;
  std::string log_level = "info";
  std::vector<std::string> rest;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--ini" && has_value) {
      ini = argv[++i];
    } else if (arg == "--socket" && has_value) {
      socket_path = argv[++i];
    } else if (arg == "--www" && has_value) {
      www = argv[++i];
    } else if (arg == "--log-level" && has_value) {
      log_level = argv[++i];
    } else if (arg == "--help" || arg == "-h") {
      usage(stdout);
      return 0;
    } else if (arg == "--version") {
      std::printf("cncd-web %s\n", cncd::kVersion);
      return 0;
    } else if (!rest.empty() || (!arg.empty() && arg[0] != '-')) {
      rest.push_back(arg);
    } else {
      std::fprintf(stderr, "cncd-web: unknown option '%s'\n", arg.c_str());
      usage(stderr);
      return 2;
    }
  }
  if (ini.empty()) {
    std::fprintf(stderr, "cncd-web: --ini is required\n");
    usage(stderr);
    return 2;
  }
  const auto level = cncd::daemon::parse_log_level(log_level);
  if (!level) {
    std::fprintf(stderr, "cncd-web: unknown log level '%s'\n", log_level.c_str());
    return 2;
  }
  auto loaded = cncd::config::load_or_report(ini, "cncd-web", std::cerr);
  if (!loaded) return cncd::config::kExitConfig;
  auto machine = cncd::web::with_web_defaults(std::move(*loaded));
  if (!rest.empty()) return cncd::web::run_admin(rest, machine.web);

  cncd::daemon::init_logging(*level);
  if (!socket_path.empty()) machine.cncd.socket_path = socket_path;
  boost::asio::io_context io;
  try {
    App app(io, std::move(machine), exe_dir() / "cncd-check");
    app.www_dir = www.empty() ? exe_dir() / ".." / "share" / "cncd" / "www" : www;
    if (const auto problem = cncd::web::prepare(app); !problem.empty()) {
      spdlog::critical("{}", problem);
      return 1;
    }
    cncd::web::Listener listener(app);
    cncd::web::StatusWatch watch(app);
    listener.start();
    watch.start();
    spdlog::info("cncd-web {} serving {}://{}:{} for cncd at {} (programs in {})", cncd::kVersion,
                 app.tls ? "https" : "http", app.web.listen, listener.endpoint().port(),
                 app.socket_path, app.programs.path().string());
    boost::asio::signal_set signals(io, SIGTERM, SIGINT);
    signals.async_wait([&](const boost::system::error_code& ec, int signal) {
      if (ec) return;
      spdlog::info("signal {}: shutting down", signal);
      listener.stop();
      watch.stop();
      for (auto* peer : std::vector(app.peers.begin(), app.peers.end()))
        peer->close_with("cncd-web is shutting down");
      // The WebSockets' close frames and their jog stops go out, then the loop ends.
      auto timer = std::make_shared<boost::asio::steady_timer>(io, std::chrono::milliseconds(300));
      timer->async_wait([&io, timer](const boost::system::error_code&) { io.stop(); });
    });
    io.run();
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  spdlog::info("stopped");
  return 0;
}
