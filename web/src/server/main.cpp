// cncd-web: the browser dashboard and WebSocket proxy of cncd (docs/web.md). A client of
// cncd's control socket like cncctl; serves the page, the programs API and /ws on
// [WEB] LISTEN:PORT. `cncd-web --ini INI user|key ...` manages its users instead.
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>
#include <boost/asio/io_context.hpp>

#include "admin_entry.hpp"
#include "app.hpp"
#include "client_start.hpp"
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
  std::filesystem::path www;
  std::vector<std::string> rest;
  auto start = cncd::daemon::start_client(argc, argv, "cncd-web", usage,
                                          [&](const std::string& arg, const char* next) {
                                            if (arg == "--www" && next != nullptr) {
                                              www = next;
                                              return 2;
                                            }
                                            if (!rest.empty() || (!arg.empty() && arg[0] != '-')) {
                                              rest.push_back(arg);
                                              return 1;
                                            }
                                            return 0;
                                          });
  if (start.exit_status) return *start.exit_status;
  auto machine = cncd::web::with_web_defaults(std::move(*start.machine));
  if (!rest.empty()) return cncd::web::run_admin(rest, machine.web);

  cncd::daemon::init_logging(start.log_level);
  if (!start.socket_path.empty()) machine.cncd.socket_path = start.socket_path;
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
    // The WebSockets' close frames and their jog stops go out, then the loop ends.
    cncd::daemon::run_until_signal(
        io,
        [&] {
          listener.stop();
          watch.stop();
          for (auto* peer : std::vector(app.peers.begin(), app.peers.end()))
            peer->close_with("cncd-web is shutting down");
        },
        std::chrono::milliseconds(300));
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
  spdlog::info("stopped");
  return 0;
}
