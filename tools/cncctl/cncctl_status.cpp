// cncctl: helpers and the readable status view shared by `status` and `watch`.
#include <cstdio>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <utility>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

json result_of(const json& response) {
  if (response.contains("error")) {
    const auto& error = response["error"];
    const std::string message = text_field(error, "message");
    throw Refused{(message.empty() ? std::string("error") : message) + " (code " +
                      std::to_string(error.value("code", 0)) + ")",
                  error.value("code", 0)};
  }
  return response.value("result", json());
}

int show(daemon::Client& client, const char* method, bool json_output, void (*print)(const json&)) {
  const json answer = result_of(client.call(method));
  if (json_output) {
    std::printf("%s\n", answer.dump(2).c_str());
  } else {
    print(answer);
  }
  return kDone;
}

std::string axes_text(const json& axes) {
  std::string out;
  char buf[64];
  if (!axes.is_object()) return out;
  for (const auto& [name, value] : axes.items()) {
    if (!value.is_number() || name.size() != 1 || name[0] < 'a' || name[0] > 'z') continue;
    std::snprintf(buf, sizeof buf, "%s%c %.4f", out.empty() ? "" : "  ", name[0] - 'a' + 'A',
                  value.get<double>());
    out += buf;
  }
  return out;
}

double number_arg(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) {
    throw UsageError{"'" + text + "' is not a number (" + what + ")"};
  }
  return value;
}

namespace {
std::string join(const json& list) {
  std::string out;
  if (!list.is_array()) return out;
  for (const auto& item : list) {
    if (!item.is_string()) continue;
    out += (out.empty() ? "" : " ") + printable(item.get<std::string>());
  }
  return out;
}

// nlohmann's value() insists on the stored type; status fields may be missing after a filter.
template <typename T>
T get(const json& object, const char* key, T fallback) {
  if (!object.is_object()) return fallback;
  const auto it = object.find(key);
  if (it == object.end() || it->is_null()) return fallback;
  try {
    // Text comes from cncd (file names, errors): never raw to the terminal.
    if constexpr (std::is_same_v<T, std::string>) return printable(it->get<std::string>());
    return it->get<T>();
  } catch (const json::exception&) {
    return fallback;
  }
}

// One line per joint: driver, drive enable, homed, then the switches and flags that are set.
void print_joints(const json& joints) {
  static constexpr std::pair<const char*, const char*> kFlags[] = {
      {"min_limit", "min-limit"},
      {"max_limit", "max-limit"},
      {"home_switch", "home-switch"},
      {"at_min_soft_limit", "at-soft-min"},
      {"at_max_soft_limit", "at-soft-max"},
      {"drive_fault", "drive-fault"},
      {"stale", "stale"},
      {"fault", "fault"}};
  int j = 0;
  for (const auto& joint : joints) {
    std::string flags;
    for (const auto& [key, label] : kFlags) {
      if (get<bool>(joint, key, false)) flags += (flags.empty() ? "" : " ") + std::string(label);
    }
    const std::string driver = get<std::string>(joint, "driver", "");
    std::printf("joint %-3d %-7s %-4s %-8s %s\n", j++, driver.empty() ? "-" : driver.c_str(),
                get<bool>(joint, "enabled", false) ? "on" : "off",
                get<bool>(joint, "homed", false) ? "homed" : "unhomed",
                flags.empty() ? "ok" : flags.c_str());
  }
}
}  // namespace

void print_status(const json& s) {
  std::printf("state     %s\n", get<std::string>(s, "state", "").c_str());
  std::printf("exec      %s (motion %s, mode %s)\n", get<std::string>(s, "exec", "").c_str(),
              get<std::string>(s, "motion", "").c_str(), get<std::string>(s, "mode", "").c_str());
  if (s.contains("joints") && s["joints"].is_array()) {
    print_joints(s["joints"]);
  } else if (s.contains("homed")) {
    std::string homed;
    for (const auto& h : s["homed"])
      homed += h.is_boolean() && h.get<bool>() ? "H " : "- ";
    std::printf("homed     %s\n", homed.c_str());
  }
  const json position = s.value("position", json::object());
  const json work = s.value("work_position", json::object());
  std::printf("commanded %s  (%s)\n", axes_text(position.value("commanded", json())).c_str(),
              get<std::string>(s, "units", "").c_str());
  std::printf("actual    %s\n", axes_text(position.value("actual", json())).c_str());
  // A machine with TCP: the tool tip in the part's frame, and the TCP state of the motion
  // and of the next move the interpreter reads.
  const json tip = s.value("tool_tip", json());
  if (tip.is_object()) {
    std::printf("tip       %s  (tool tip, part's frame)\n",
                axes_text(tip.value("commanded", json())).c_str());
    std::printf("tip act   %s\n", axes_text(tip.value("actual", json())).c_str());
  }
  const json tcp = s.value("tcp", json());
  if (tcp.is_object()) {
    std::printf("tcp       motion %s, next move %s\n",
                get<bool>(tcp, "motion", false) ? "on" : "off",
                get<bool>(tcp, "programmed", false) ? "on" : "off");
  }
  if (get<std::string>(s, "position_restored", "") == "unclean") {
    std::printf("          (started from positions saved before an unclean shutdown)\n");
  }
  const json offsets = s.value("offsets", json::object());
  if (!work.empty()) {
    std::printf("work      %s  (%s)\n", axes_text(work.value("commanded", json())).c_str(),
                get<std::string>(offsets, "coord_system", "").c_str());
  }
  std::printf("velocity  %.3f   to go %.4f\n", get<double>(s, "velocity", 0.0),
              get<double>(s, "distance_to_go", 0.0));
  const json overrides = s.value("overrides", json::object());
  if (!overrides.empty()) {
    std::printf("override  feed %.0f %%  rapid %.0f %%  spindle %.0f %%\n",
                100.0 * get<double>(overrides, "feed", 1.0),
                100.0 * get<double>(overrides, "rapid", 1.0),
                100.0 * get<double>(overrides, "spindle", 1.0));
  }
  const json tool = s.value("tool", json::object());
  const json spindle = s.value("spindle", json::object());
  const json coolant = s.value("coolant", json::object());
  const int direction = get<int>(spindle, "direction", 0);
  std::printf(
      "tool      T%d  length %s   spindle %s %.0f   coolant%s%s%s\n", get<int>(tool, "number", 0),
      axes_text(tool.value("length_offset", json())).c_str(),
      direction > 0   ? "cw"
      : direction < 0 ? "ccw"
                      : "off",
      get<double>(spindle, "speed", 0.0), get<bool>(coolant, "mist", false) ? " mist" : "",
      get<bool>(coolant, "flood", false) ? " flood" : "",
      !get<bool>(coolant, "mist", false) && !get<bool>(coolant, "flood", false) ? " off" : "");
  if (s.contains("gcodes")) {
    std::printf("codes     %s %s\n", join(s["gcodes"]).c_str(), join(s["mcodes"]).c_str());
  }
  const json p = s.value("program", json::object());
  const std::string path = get<std::string>(p, "path", "");
  if (!path.empty()) {
    const auto total = get<unsigned long long>(p, "total_lines", 0ULL);
    if (get<std::string>(s, "exec", "idle") == "idle") {
      std::printf("program   %s  (%llu lines)", path.c_str(), total);
    } else {
      std::printf("program   %s  line %d of %llu  %.0f%%  %.1f s", path.c_str(),
                  get<int>(p, "line", 0), total, 100.0 * get<double>(p, "progress", 0.0),
                  get<double>(p, "elapsed_s", 0.0));
      if (p.contains("remaining_s") && p["remaining_s"].is_number())
        std::printf("  %.1f s left", p["remaining_s"].get<double>());
    }
    if (p.contains("estimated_s") && p["estimated_s"].is_number())
      std::printf("  (estimated %.1f s)", p["estimated_s"].get<double>());
    const std::string result = get<std::string>(p, "result", "");
    if (!result.empty()) std::printf("  last run: %s", result.c_str());
    std::printf("\n");
    const std::string error = get<std::string>(p, "error", "");
    if (!error.empty()) std::printf("error     %s\n", error.c_str());
  }
  const std::string fault = get<std::string>(s, "fault", "");
  if (!fault.empty()) std::printf("fault     %s\n", fault.c_str());
}

}  // namespace cncd::cncctl
