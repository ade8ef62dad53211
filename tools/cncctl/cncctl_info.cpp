// cncctl info: cncd's version and the machine it runs (system.info).
#include <cstdio>
#include <string>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

namespace {
std::string join(const json& list) {
  std::string out;
  if (!list.is_array()) return out;
  for (const auto& item : list)
    out += (out.empty() ? "" : " ") +
           (item.is_string() ? printable(item.get<std::string>()) : item.dump());
  return out;
}
}  // namespace

int info(daemon::Client& client, const Args& args, bool json_output) {
  if (args.size() != 1) throw UsageError{"info takes no arguments"};
  const json result = result_of(client.call("system.info"));
  if (json_output) {
    std::printf("%s\n", result.dump(2).c_str());
    return kDone;
  }
  const json machine = result.value("machine", json::object());
  std::printf("cncd      %s (protocol %s)\n", text_field(result, "version").c_str(),
              result.value("protocol_version", json()).dump().c_str());
  std::printf("machine   %s\n", text_field(machine, "name").c_str());
  std::printf("config    %s\n", text_field(machine, "config").c_str());
  std::printf("axes      %s (%s)\n", join(machine.value("axes", json())).c_str(),
              text_field(machine, "units").c_str());
  std::printf("joints    %s: %s\n", machine.value("joints", json()).dump().c_str(),
              join(machine.value("drivers", json())).c_str());
  std::printf("servo     %s ns\n", machine.value("servo_period_ns", json()).dump().c_str());
  return kDone;
}

}  // namespace cncd::cncctl
