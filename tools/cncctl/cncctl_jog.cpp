// cncctl jog: continuous and incremental jogs of one axis.
#include <chrono>
#include <cstdio>
#include <thread>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

namespace {

// Waits until the machine no longer jogs; kFailed when a fault ends the jog.
int wait_jog_done(daemon::Client& client, bool json_output) {
  json s;
  for (;;) {
    s = result_of(client.call("status.get"));
    if (s.value("motion", "") != "jogging") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (json_output) {
    std::printf("%s\n", s.dump(2).c_str());
  } else {
    std::printf("%s\n", axes_text(s["position"]["commanded"]).c_str());
  }
  if (!s.value("fault", "").empty()) {
    std::fprintf(stderr, "cncctl: jog failed: %s\n", text_field(s, "fault").c_str());
    return kFailed;
  }
  return kDone;
}

}  // namespace

int jog(daemon::Client& client, const Args& args, bool json_output) {
  if (args.size() < 3) {
    throw UsageError{
        "jog needs an axis and +/-VELOCITY, --increment DIST or stop, "
        "e.g. cncctl jog X +10"};
  }
  const std::string& axis = args[1];
  if (args[2] == "stop") {
    if (args.size() != 3) throw UsageError{"jog AXIS stop takes nothing more"};
    result_of(client.call("jog.stop", json{{"axis", axis}}));
    return wait_jog_done(client, json_output);
  }
  if (args[2] == "--increment") {
    if (args.size() != 4 && !(args.size() == 6 && args[4] == "--velocity")) {
      throw UsageError{"jog AXIS --increment DIST [--velocity V]"};
    }
    json params{{"axis", axis}, {"distance", number_arg(args[3], "--increment")}};
    if (args.size() == 6) params["velocity"] = number_arg(args[5], "--velocity");
    result_of(client.call("jog.increment", params));
    return wait_jog_done(client, json_output);
  }
  if (args.size() != 3) throw UsageError{"jog AXIS +/-VELOCITY takes nothing more"};
  const json result = result_of(client.call(
      "jog.start", json{{"axis", axis}, {"velocity", number_arg(args[2], "velocity")}}));
  if (json_output) std::printf("%s\n", result.dump().c_str());
  return kDone;
}

}  // namespace cncd::cncctl
