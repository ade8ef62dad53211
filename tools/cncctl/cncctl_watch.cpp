// cncctl watch: a live status view through a subscription, redrawn in place until Ctrl-C.
#include <unistd.h>

#include <csignal>
#include <cstdio>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

namespace {
volatile std::sig_atomic_t g_stop = 0;

void on_signal(int) {
  g_stop = 1;
}

// Without SA_RESTART, so that the wait for the next update returns at once.
void catch_stop_signals() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}
}  // namespace

int watch(daemon::Client& client, const Args& args, bool json_output) {
  int interval_ms = 200;
  long count = 0;  // updates to show before exiting; 0 = until interrupted
  for (std::size_t i = 1; i < args.size(); ++i) {
    if ((args[i] == "--interval" || args[i] == "--count") && i + 1 < args.size()) {
      const double value = number_arg(args[i + 1], args[i]);
      if (value < 1 || value != static_cast<double>(static_cast<long>(value))) {
        throw UsageError{args[i] + " needs a whole number of at least 1"};
      }
      if (args[i] == "--interval") {
        interval_ms = static_cast<int>(value);
      } else {
        count = static_cast<long>(value);
      }
      ++i;
    } else {
      throw UsageError{"watch takes --interval MS and --count N, not '" + args[i] + "'"};
    }
  }
  catch_stop_signals();
  result_of(client.call("status.subscribe", json{{"interval_ms", interval_ms}}));
  const bool tty = isatty(STDOUT_FILENO) != 0 && !json_output;
  if (tty) std::printf("\033[?25l");  // hide the cursor while redrawing
  json status = json::object();
  long shown = 0;
  while (g_stop == 0 && (count == 0 || shown < count)) {
    const auto line = client.try_read_line(250);
    if (!line) continue;
    const json message = json::parse(*line, nullptr, false);
    if (!message.is_object() || message.value("method", "") != "status.update") continue;
    const json& params = message["params"];
    if (params.value("full", false)) status = json::object();
    status.merge_patch(params.value("changed", json::object()));
    ++shown;
    if (json_output) {
      std::printf("%s\n", status.dump().c_str());
    } else {
      if (tty) std::printf("\033[H\033[2J");
      print_status(status);
      if (!tty) std::printf("\n");
    }
    std::fflush(stdout);
  }
  if (tty) std::printf("\033[?25h");
  return kDone;
}

}  // namespace cncd::cncctl
