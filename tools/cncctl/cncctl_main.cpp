// cncctl: command-line client for cncd's control socket. Exit status: see cncctl.hpp.
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "client.hpp"
#include "cncctl.hpp"
#include "version.hpp"

namespace {

using nlohmann::json;
using namespace cncd::cncctl;

void usage(std::FILE* out) {
  std::fputs(
      "usage: cncctl [--socket PATH] [--json] COMMAND [ARGS]\n"
      "\n"
      "commands:\n"
      "  status              show the machine's state, positions, tool, codes and program\n"
      "  watch [--interval MS] [--count N]\n"
      "                      live status view, redrawn in place until Ctrl-C\n"
      "  estop               latch emergency stop\n"
      "  reset               leave emergency stop (the machine stays off)\n"
      "  on | off            turn the machine on or off\n"
      "  home [JOINT...]     home all joints (or the given ones) and wait until homed\n"
      "  run FILE [--from LINE]\n"
      "                      open FILE, run it (from LINE) and follow it to the end\n"
      "  open FILE           open FILE for run or step\n"
      "  step [FILE]         run one more line of the open program (or of FILE) and wait\n"
      "  pause | resume      feed hold (during a thread or tap: at its end, and says so)\n"
      "                      and continue\n"
      "  tool-done T<n>      tool n, the one a program's M6 waits for, is in: go on\n"
      "  abort               stop the running program; returns once the machine is at rest\n"
      "  mdi LINE            execute one block; returns when it has finished\n"
      "  jog AXIS +/-VELOCITY\n"
      "                      jog AXIS (e.g. X) at VELOCITY units/s until 'jog AXIS stop'\n"
      "  jog AXIS --increment DIST [--velocity V]\n"
      "                      move AXIS by DIST and wait until it is there\n"
      "  jog AXIS stop       stop a jog under control and wait until at rest\n"
      "                      (AXIS J0, J1, ...: that joint alone, as LinuxCNC's joint mode;\n"
      "                      refused on a homed joint that moves with an axis)\n"
      "  override feed|rapid|spindle PERCENT\n"
      "                      set an override, e.g. 'override feed 80' (100 = as programmed)\n"
      "  tools               list the tool table\n"
      "  tools set T<n> [P<pocket>] [Z<offset> ...] [D<diameter>] [;comment]\n"
      "                      change (or add) one tool\n"
      "  offsets             list the coordinate systems G54..G59.3 and G92\n"
      "  offsets set G55 [X<origin> ...] [R<rotation>]\n"
      "                      set one coordinate system's origin (machine coordinates)\n"
      "  jobs [stats] [--since YYYY-MM-DD] [--limit N]\n"
      "                      the programs run: when, how they ended, cycle time, parts\n"
      "  errors [--since SEQ]\n"
      "                      list recent errors and events (those after SEQ)\n"
      "  info                cncd's version and the machine it runs\n"
      "\n"
      "--json prints cncd's answer (or the final status) as JSON.\n"
      "The socket defaults to $CNCD_SOCKET, else /run/cncd/cncd.sock.\n"
      "Exit status: 0 done, 1 failed (program error, fault, file not written), 2 refused (state,\n"
      "permission, bad value), 64 usage, 69 cncd not reachable or connection lost.\n",
      out);
}

int wait_homed(cncd::daemon::Client& client, const std::vector<int>& joints) {
  for (int tries = 0; tries < 6000; ++tries) {
    const json s = result_of(client.call("status.get"));
    if (!s.value("fault", "").empty()) {
      std::fprintf(stderr, "cncctl: homing failed: %s\n", text_field(s, "fault").c_str());
      return kFailed;
    }
    bool done = true;
    const auto& homed = s["homed"];
    for (std::size_t j = 0; j < homed.size(); ++j) {
      const bool wanted = joints.empty() || std::find(joints.begin(), joints.end(),
                                                      static_cast<int>(j)) != joints.end();
      if (wanted && !homed[j].get<bool>()) done = false;
    }
    if (done && s.value("motion", "") == "idle") return kDone;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::fprintf(stderr, "cncctl: homing did not finish within 5 minutes\n");
  return kFailed;
}

// A tool change the program waits for: prompts once and answers tool.change_done for the tool
// the prompt named when a line comes on standard input (another terminal may answer it with
// 'cncctl tool-done T' meanwhile).
class ToolPrompt {
 public:
  void update(cncd::daemon::Client& client, const json& wait, bool tty) {
    const bool waiting = wait.is_object() && wait.value("kind", "") == "tool_change" &&
                         wait.contains("tool") && wait["tool"].is_number_integer();
    if (!waiting) {
      prompted_ = false;
      return;
    }
    const int tool = wait["tool"].get<int>();
    // A wait that started later than the one prompted for is another change, of the same tool
    // maybe: two M6 in a row whose gap no status showed.
    const double since = wait.value("since", 0.0);
    const bool newer = since < since_;
    since_ = since;
    if (!prompted_ || tool != tool_ || newer) {
      prompted_ = true;
      tool_ = tool;
      // What was typed before this prompt (an Enter for the last change, a key hit by
      // accident) must not answer it.
      if (isatty(STDIN_FILENO) != 0) ::tcflush(STDIN_FILENO, TCIFLUSH);
      std::fprintf(stderr, "%s%s\n", tty ? "\r\033[K" : "", text_field(wait, "message").c_str());
    }
    if (stdin_closed_) return;
    pollfd fd{STDIN_FILENO, POLLIN, 0};
    if (::poll(&fd, 1, 0) <= 0) return;
    char buffer[256];
    const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
    if (n <= 0) {
      stdin_closed_ = true;  // no operator here: 'cncctl tool-done' answers
      return;
    }
    if (std::memchr(buffer, '\n', static_cast<std::size_t>(n)) == nullptr) return;
    // Answered meanwhile from elsewhere, or the program has moved on to another change: the
    // refusal says so, and the next status shows what is waiting now.
    const json reply = client.call("tool.change_done", json{{"tool", tool_}});
    (void)reply;
  }

 private:
  bool prompted_ = false;
  int tool_ = -1;
  double since_ = 0;
  bool stdin_closed_ = false;
};

int follow_program(cncd::daemon::Client& client, bool json_output) {
  const bool tty = isatty(STDOUT_FILENO) != 0 && !json_output;
  int last_line = -1;
  ToolPrompt prompt;
  std::string last_wait;
  for (;;) {
    const json s = result_of(client.call("status.get"));
    const json wait = s.contains("wait") ? s["wait"] : json();
    prompt.update(client, wait, tty);
    // Other waits (the spindle coming up to speed, an input, a user M code) are said once.
    const std::string wait_kind = wait.is_object() ? wait.value("kind", "") : "";
    if (wait_kind != last_wait && !wait_kind.empty() && wait_kind != "tool_change" &&
        !json_output) {
      std::printf("%s%s\n", tty ? "\r\033[K" : "", text_field(wait, "message").c_str());
      std::fflush(stdout);
    }
    last_wait = wait_kind;
    const auto& p = s["program"];
    const std::string exec = s.value("exec", "");
    const int line = p.value("line", 0);
    if (exec != "idle" && !json_output && (tty || line != last_line)) {
      const double progress = p.value("progress", 0.0);
      const int filled = static_cast<int>(progress * 20.0 + 0.5);
      // Remaining time from the daemon's plan estimate, when it has one for this run.
      char left[48] = "";
      if (p.contains("remaining_s") && p["remaining_s"].is_number())
        std::snprintf(left, sizeof left, "  %.1f s left", p["remaining_s"].get<double>());
      std::printf("%s[%.*s%.*s] %3.0f%%  line %d/%llu  %s  %.1f s%s%s", tty ? "\r\033[K" : "",
                  filled, "####################", 20 - filled, "                    ",
                  100.0 * progress, line,
                  static_cast<unsigned long long>(p.value("total_lines", 0ULL)),
                  axes_text(s["position"]["commanded"]).c_str(), p.value("elapsed_s", 0.0), left,
                  tty ? "" : "\n");
      std::fflush(stdout);
      last_line = line;
    }
    if (exec == "idle") {
      if (tty) std::printf("\r\033[K");
      const std::string result = text_field(p, "result");
      if (json_output) {
        std::printf("%s\n", s.dump(2).c_str());
      } else {
        std::printf("%s in %.3f s; position %s\n", result.c_str(), p.value("elapsed_s", 0.0),
                    axes_text(s["position"]["commanded"]).c_str());
      }
      if (result != "done") {
        std::fprintf(stderr, "cncctl: program %s: %s\n", result.c_str(),
                     text_field(p, "error").c_str());
        return kFailed;
      }
      return kDone;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(tty ? 100 : 50));
  }
}

json open_program(cncd::daemon::Client& client, const std::string& file) {
  std::error_code ec;
  const auto path = std::filesystem::absolute(file, ec);
  return result_of(client.call("program.open", json{{"path", path.string()}}));
}

// program.step has been sent: waits until the line has been carried out.
int follow_step(cncd::daemon::Client& client, bool json_output) {
  for (;;) {
    const json s = result_of(client.call("status.get"));
    const std::string exec = s.value("exec", "");
    if (exec != "running") {
      const auto& p = s["program"];
      if (json_output) {
        std::printf("%s\n", s.dump(2).c_str());
      } else if (exec == "paused") {
        std::printf("line %d/%llu  %s\n", p.value("line", 0),
                    static_cast<unsigned long long>(p.value("total_lines", 0ULL)),
                    axes_text(s["work_position"]["commanded"]).c_str());
      } else {
        std::printf("%s; position %s\n", text_field(p, "result").c_str(),
                    axes_text(s["work_position"]["commanded"]).c_str());
      }
      if (exec == "idle" && p.value("result", "") != "done") {
        std::fprintf(stderr, "cncctl: program %s: %s\n", text_field(p, "result").c_str(),
                     text_field(p, "error").c_str());
        return kFailed;
      }
      return kDone;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// program.run / program.step answered. A run that ended in error before it moved answers with
// that error (1003); it did run, and the status that follows tells how it ended.
void started(const json& response) {
  if (response.contains("error") && response["error"].value("code", 0) == 1003) return;
  result_of(response);
}

int run_command(cncd::daemon::Client& client, const std::vector<std::string>& args,
                bool json_output) {
  const std::string& command = args[0];
  auto simple = [&](const char* method) {
    const json result = result_of(client.call(method));
    if (json_output) std::printf("%s\n", result.dump().c_str());
    return kDone;
  };
  if (command == "status") return show(client, "status.get", json_output, print_status);
  static const std::vector<std::string> kTakeArgs = {
      "home",    "run", "mdi",      "open",   "step",      "watch", "tools",
      "offsets", "jog", "override", "errors", "tool-done", "jobs"};
  if (args.size() > 1 &&
      std::find(kTakeArgs.begin(), kTakeArgs.end(), command) == kTakeArgs.end()) {
    std::fprintf(stderr, "cncctl: '%s' takes no arguments\n", command.c_str());
    return kUsage;
  }
  if (command == "estop") return simple("machine.estop");
  if (command == "reset") return simple("machine.reset");
  if (command == "on") return simple("machine.on");
  if (command == "off") return simple("machine.off");
  if (command == "abort") return simple("program.abort");
  if (command == "pause") {
    // A hold during a thread or a tap takes effect at its end: the answer says so.
    const json result = result_of(client.call("program.pause"));
    if (json_output) {
      std::printf("%s\n", result.dump().c_str());
    } else if (result.contains("message")) {
      std::printf("%s\n", printable(result.value("message", "")).c_str());
    }
    return kDone;
  }
  if (command == "resume") return simple("program.resume");
  if (command == "tool-done") {
    // The tool is named: an answer meant for one change never lets another go on.
    const std::string usage = "tool-done needs the tool the prompt names, e.g. 'tool-done T3'";
    if (args.size() != 2) throw UsageError{usage};
    std::string word = args[1];
    if (!word.empty() && (word[0] == 'T' || word[0] == 't')) word.erase(0, 1);
    char* end = nullptr;
    const long tool = std::strtol(word.c_str(), &end, 10);
    if (word.empty() || *end != '\0' || tool < 0 || tool > 99999) throw UsageError{usage};
    const json result = result_of(client.call("tool.change_done", json{{"tool", tool}}));
    if (json_output) std::printf("%s\n", result.dump().c_str());
    return kDone;
  }
  if (command == "mdi") {
    std::string line;
    for (std::size_t i = 1; i < args.size(); ++i)
      line += (i > 1 ? " " : "") + args[i];
    if (line.empty()) {
      std::fprintf(stderr, "cncctl: mdi needs a block, e.g. cncctl mdi G0 X10\n");
      return kUsage;
    }
    const json response = client.call("mdi.execute", json{{"line", line}}, 24 * 3600 * 1000);
    if (response.contains("error") && response["error"].value("code", 0) == 1003) {
      std::fprintf(stderr, "cncctl: mdi failed: %s\n",
                   text_field(response["error"], "message").c_str());
      return kFailed;
    }
    result_of(response);
    if (json_output) std::printf("%s\n", response["result"].dump().c_str());
    return kDone;
  }
  if (command == "jobs") return jobs(client, args, json_output);
  if (command == "errors") {
    if (args.size() != 1 && (args.size() != 3 || args[1] != "--since"))
      throw UsageError{"errors takes only --since SEQ"};
    const double since = args.size() == 3 ? number_arg(args[2], "--since") : 0.0;
    if (since < 0 || since != static_cast<double>(static_cast<long long>(since)))
      throw UsageError{"--since needs an event sequence number"};
    const json list = result_of(
        client.call("errors.list", json{{"since", static_cast<unsigned long long>(since)}}));
    if (json_output) {
      std::printf("%s\n", list.dump(2).c_str());
      return kDone;
    }
    for (const auto& e : list["events"]) {
      const auto when = static_cast<std::time_t>(e.value("time", 0.0));
      char stamp[32];
      std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", std::localtime(&when));
      std::printf("%6llu %s %-7s %-8s %s\n", static_cast<unsigned long long>(e.value("seq", 0ULL)),
                  stamp, text_field(e, "level").c_str(), text_field(e, "kind").c_str(),
                  text_field(e, "message").c_str());
    }
    return kDone;
  }
  if (command == "home") {
    std::vector<int> joints;
    for (std::size_t i = 1; i < args.size(); ++i) {
      char* end = nullptr;
      const long j = std::strtol(args[i].c_str(), &end, 10);
      if (end == args[i].c_str() || *end != '\0' || j < 0) {
        std::fprintf(stderr, "cncctl: '%s' is not a joint number\n", args[i].c_str());
        return kUsage;
      }
      joints.push_back(static_cast<int>(j));
    }
    json params = json::object();
    if (!joints.empty()) params["joints"] = joints;
    const json result = result_of(client.call("machine.home", params));
    const int status = wait_homed(client, joints);
    if (json_output && status == kDone) std::printf("%s\n", result.dump().c_str());
    return status;
  }
  if (command == "run") {
    std::string file;
    json params = json::object();
    for (std::size_t i = 1; i < args.size(); ++i) {
      if (args[i] == "--from" && i + 1 < args.size()) {
        const double line = number_arg(args[++i], "--from");
        if (line < 1 || line != static_cast<double>(static_cast<long>(line))) {
          throw UsageError{"--from needs a line number"};
        }
        params["from_line"] = static_cast<long>(line);
      } else if (file.empty() && args[i].rfind("--", 0) != 0) {
        file = args[i];
      } else {
        throw UsageError{"run takes one program file and --from LINE"};
      }
    }
    if (file.empty()) throw UsageError{"run needs a program file"};
    open_program(client, file);
    started(client.call("program.run", params));
    return follow_program(client, json_output);
  }
  if (command == "open") {
    if (args.size() != 2) throw UsageError{"open takes one program file"};
    const json result = open_program(client, args[1]);
    if (json_output) std::printf("%s\n", result.dump().c_str());
    return kDone;
  }
  if (command == "step") {
    if (args.size() > 2) throw UsageError{"step takes at most one program file"};
    if (args.size() == 2) open_program(client, args[1]);
    started(client.call("program.step"));
    return follow_step(client, json_output);
  }
  if (command == "watch") return watch(client, args, json_output);
  if (command == "jog") return jog(client, args, json_output);
  if (command == "override") return override_command(client, args, json_output);
  if (command == "info") return info(client, args, json_output);
  if (command == "tools") return tools(client, args, json_output);
  if (command == "offsets") return offsets(client, args, json_output);
  std::fprintf(stderr, "cncctl: unknown command '%s'\n", command.c_str());
  usage(stderr);
  return kUsage;
}

}  // namespace

int main(int argc, char** argv) {
  const char* env_socket = std::getenv("CNCD_SOCKET");
  std::string socket_path = env_socket != nullptr ? env_socket : "/run/cncd/cncd.sock";
  bool json_output = false;
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--socket") {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "cncctl: --socket needs a path\n");
        return kUsage;
      }
      socket_path = argv[++i];
    } else if (arg == "--json") {
      json_output = true;
    } else if (arg == "--help" || arg == "-h") {
      usage(stdout);
      return kDone;
    } else if (arg == "--version") {
      std::printf("cncctl %s\n", cncd::kVersion);
      return kDone;
    } else {
      args.push_back(arg);
    }
  }
  if (args.empty()) {
    usage(stderr);
    return kUsage;
  }
  cncd::daemon::Client client;
  if (const auto error = client.connect(socket_path); !error.empty()) {
    std::fprintf(stderr, "cncctl: %s\n", error.c_str());
    return kUnavailable;
  }
  try {
    return run_command(client, args, json_output);
  } catch (const Refused& refused) {
    // The machine tried and failed (a drive fault, a file that cannot be written), as against
    // a request declined in the state it is in.
    const bool failed = refused.code == 1007 || refused.code == 1008;
    std::fprintf(stderr, "cncctl: %s: %s: %s\n", args[0].c_str(), failed ? "failed" : "refused",
                 refused.message.c_str());
    return failed ? kFailed : kRefused;
  } catch (const UsageError& error) {
    std::fprintf(stderr, "cncctl: %s\n", error.message.c_str());
    return kUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cncctl: %s\n", e.what());
    return kUnavailable;
  }
}
