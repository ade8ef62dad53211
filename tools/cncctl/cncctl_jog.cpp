// cncctl jog: continuous and incremental jogs of one axis, or of one joint (J0, J1, ...).
#include <cctype>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

namespace {

// The jog's target in a request: {"axis": "X"}, or {"joint": 2} for "J2" (joint mode).
json target(const std::string& name) {
  const bool joint = name.size() > 1 && name.size() <= 3 && (name[0] == 'J' || name[0] == 'j') &&
                     name.find_first_not_of("0123456789", 1) == std::string::npos;
  if (joint) return json{{"joint", std::stoi(name.substr(1))}};
  return json{{"axis", name}};
}

// The joints' commanded positions, as axes_text writes the axes: "J0 1.0000  J1 2.0000".
std::string joints_text(const json& joints) {
  std::string text;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    char part[64];
    std::snprintf(part, sizeof part, "%sJ%zu %.4f", j == 0 ? "" : "  ", j,
                  joints[j].value("commanded", 0.0));
    text += part;
  }
  return text;
}

// Waits until the machine no longer jogs; kFailed when a fault ends the jog.
int wait_jog_done(daemon::Client& client, bool json_output, bool joint) {
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
    if (joint && s.contains("joints")) std::printf("%s\n", joints_text(s["joints"]).c_str());
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
  const json axis = target(args[1]);
  const bool joint = axis.contains("joint");
  if (args[2] == "stop") {
    if (args.size() != 3) throw UsageError{"jog AXIS stop takes nothing more"};
    result_of(client.call("jog.stop", axis));
    return wait_jog_done(client, json_output, joint);
  }
  if (args[2] == "--increment") {
    if (args.size() != 4 && !(args.size() == 6 && args[4] == "--velocity")) {
      throw UsageError{"jog AXIS --increment DIST [--velocity V]"};
    }
    json params = axis;
    params["distance"] = number_arg(args[3], "--increment");
    if (args.size() == 6) params["velocity"] = number_arg(args[5], "--velocity");
    result_of(client.call("jog.increment", params));
    return wait_jog_done(client, json_output, joint);
  }
  if (args.size() != 3) throw UsageError{"jog AXIS +/-VELOCITY takes nothing more"};
  json params = axis;
  params["velocity"] = number_arg(args[2], "velocity");
  const json result = result_of(client.call("jog.start", params));
  if (json_output) std::printf("%s\n", result.dump().c_str());
  return kDone;
}

}  // namespace cncd::cncctl
