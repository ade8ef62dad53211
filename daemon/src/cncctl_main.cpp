// cncctl: command-line client for cncd's control socket.
//
// Exit status: 0 done, 1 failed (the program or the machine reported a failure),
// 2 refused (cncd declined the request), 64 usage, 69 cncd not reachable.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "client.hpp"
#include "version.hpp"

namespace {

using nlohmann::json;

constexpr int kDone = 0;
constexpr int kFailed = 1;
constexpr int kRefused = 2;
constexpr int kUsage = 64;
constexpr int kUnavailable = 69;

void usage(std::FILE* out) {
  std::fputs(
      "usage: cncctl [--socket PATH] [--json] COMMAND [ARGS]\n"
      "\n"
      "commands:\n"
      "  status           show the machine's state, position and program\n"
      "  estop            latch emergency stop\n"
      "  reset            leave emergency stop (the machine stays off)\n"
      "  on | off         turn the machine on or off\n"
      "  home [JOINT...]  home all joints (or the given ones) and wait until homed\n"
      "  run FILE         open FILE, run it and follow it to the end\n"
      "  pause | resume   feed hold and continue\n"
      "  abort            stop the running program; returns once the machine is at rest\n"
      "  mdi LINE         execute one block; returns when it has finished\n"
      "  errors           list recent errors and events\n"
      "\n"
      "The socket defaults to $CNCD_SOCKET, else /run/cncd/cncd.sock.\n"
      "Exit status: 0 done, 1 failed, 2 refused, 64 usage, 69 cncd not reachable.\n",
      out);
}

struct Refused {
  std::string message;
};

json result_of(const json& response) {
  if (response.contains("error")) {
    const auto& error = response["error"];
    throw Refused{error.value("message", std::string("error")) + " (code " +
                  std::to_string(error.value("code", 0)) + ")"};
  }
  return response.value("result", json());
}

std::string axes_text(const json& axes) {
  std::string out;
  char buf[64];
  for (const auto& [name, value] : axes.items()) {
    std::snprintf(buf, sizeof buf, "%s%c %.4f", out.empty() ? "" : "  ", name[0] - 'a' + 'A',
                  value.get<double>());
    out += buf;
  }
  return out;
}

void print_status(const json& s) {
  std::printf("state     %s\n", s.value("state", "").c_str());
  std::printf("exec      %s (motion %s)\n", s.value("exec", "").c_str(),
              s.value("motion", "").c_str());
  std::string homed;
  for (const auto& h : s["homed"])
    homed += h.get<bool>() ? "H " : "- ";
  std::printf("homed     %s\n", homed.c_str());
  std::printf("commanded %s  (%s)\n", axes_text(s["position"]["commanded"]).c_str(),
              s.value("units", "").c_str());
  std::printf("actual    %s\n", axes_text(s["position"]["actual"]).c_str());
  const auto& p = s["program"];
  if (!p.value("path", "").empty()) {
    const auto total = static_cast<unsigned long long>(p.value("total_lines", 0ULL));
    if (s.value("exec", "") == "idle") {
      std::printf("program   %s  (%llu lines)", p.value("path", "").c_str(), total);
    } else {
      std::printf("program   %s  line %d of %llu", p.value("path", "").c_str(), p.value("line", 0),
                  total);
    }
    if (!p.value("result", "").empty())
      std::printf("  last run: %s", p.value("result", "").c_str());
    std::printf("\n");
    if (!p.value("error", "").empty()) std::printf("error     %s\n", p.value("error", "").c_str());
  }
  if (!s.value("fault", "").empty()) std::printf("fault     %s\n", s.value("fault", "").c_str());
}

int wait_homed(cncd::daemon::Client& client, const std::vector<int>& joints) {
  for (int tries = 0; tries < 6000; ++tries) {
    const json s = result_of(client.call("status.get"));
    if (!s.value("fault", "").empty()) {
      std::fprintf(stderr, "cncctl: homing failed: %s\n", s.value("fault", "").c_str());
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

int follow_program(cncd::daemon::Client& client, bool json_output) {
  const bool tty = isatty(STDOUT_FILENO) != 0 && !json_output;
  int last_line = -1;
  for (;;) {
    const json s = result_of(client.call("status.get"));
    const auto& p = s["program"];
    const std::string exec = s.value("exec", "");
    const int line = p.value("line", 0);
    if (exec != "idle" && !json_output && (tty || line != last_line)) {
      std::printf("%sline %d/%llu  %s  %.1f s%s", tty ? "\r\033[K" : "", line,
                  static_cast<unsigned long long>(p.value("total_lines", 0ULL)),
                  axes_text(s["position"]["commanded"]).c_str(), p.value("elapsed_s", 0.0),
                  tty ? "" : "\n");
      std::fflush(stdout);
      last_line = line;
    }
    if (exec == "idle") {
      if (tty) std::printf("\r\033[K");
      const std::string result = p.value("result", "");
      if (json_output) {
        std::printf("%s\n", s.dump(2).c_str());
      } else {
        std::printf("%s in %.3f s; position %s\n", result.c_str(), p.value("elapsed_s", 0.0),
                    axes_text(s["position"]["commanded"]).c_str());
      }
      if (result != "done") {
        std::fprintf(stderr, "cncctl: program %s: %s\n", result.c_str(),
                     p.value("error", "").c_str());
        return kFailed;
      }
      return kDone;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(tty ? 100 : 50));
  }
}

int run_command(cncd::daemon::Client& client, const std::vector<std::string>& args,
                bool json_output) {
  const std::string& command = args[0];
  auto simple = [&](const char* method) {
    const json result = result_of(client.call(method));
    if (json_output) std::printf("%s\n", result.dump().c_str());
    return kDone;
  };
  if (command == "status") {
    const json s = result_of(client.call("status.get"));
    if (json_output) {
      std::printf("%s\n", s.dump(2).c_str());
    } else {
      print_status(s);
    }
    return kDone;
  }
  if (args.size() > 1 && command != "home" && command != "run" && command != "mdi") {
    std::fprintf(stderr, "cncctl: '%s' takes no arguments\n", command.c_str());
    return kUsage;
  }
  if (command == "estop") return simple("machine.estop");
  if (command == "reset") return simple("machine.reset");
  if (command == "on") return simple("machine.on");
  if (command == "off") return simple("machine.off");
  if (command == "abort") return simple("program.abort");
  if (command == "pause") return simple("program.pause");
  if (command == "resume") return simple("program.resume");
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
                   response["error"].value("message", "").c_str());
      return kFailed;
    }
    result_of(response);
    if (json_output) std::printf("%s\n", response["result"].dump().c_str());
    return kDone;
  }
  if (command == "errors") {
    const json list = result_of(client.call("errors.list", json{{"since", 0}}));
    if (json_output) {
      std::printf("%s\n", list.dump(2).c_str());
      return kDone;
    }
    for (const auto& e : list["events"]) {
      const auto when = static_cast<std::time_t>(e.value("time", 0.0));
      char stamp[32];
      std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", std::localtime(&when));
      std::printf("%6llu %s %-7s %-8s %s\n", static_cast<unsigned long long>(e.value("seq", 0ULL)),
                  stamp, e.value("level", "").c_str(), e.value("kind", "").c_str(),
                  e.value("message", "").c_str());
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
    result_of(client.call("machine.home", params));
    return wait_homed(client, joints);
  }
  if (command == "run") {
    if (args.size() != 2) {
      std::fprintf(stderr, "cncctl: run takes one program file\n");
      return kUsage;
    }
    std::error_code ec;
    const auto path = std::filesystem::absolute(args[1], ec);
    result_of(client.call("program.open", json{{"path", path.string()}}));
    result_of(client.call("program.run"));
    return follow_program(client, json_output);
  }
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
    std::fprintf(stderr, "cncctl: %s: refused: %s\n", args[0].c_str(), refused.message.c_str());
    return kRefused;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cncctl: %s\n", e.what());
    return kUnavailable;
  }
}
