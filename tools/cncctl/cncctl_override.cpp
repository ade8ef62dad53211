// cncctl override: feed, rapid and spindle overrides in percent.
#include <cstdio>
#include <string>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

int override_command(daemon::Client& client, const Args& args, bool json_output) {
  if (args.size() != 3 || (args[1] != "feed" && args[1] != "rapid" && args[1] != "spindle")) {
    throw UsageError{
        "override needs feed, rapid or spindle and a percentage, e.g. "
        "cncctl override feed 80"};
  }
  std::string text = args[2];
  if (!text.empty() && text.back() == '%') text.pop_back();
  const double percent = number_arg(text, "override percentage");
  const json result =
      result_of(client.call("override." + args[1], json{{"value", percent / 100.0}}));
  if (json_output) {
    std::printf("%s\n", result.dump().c_str());
  } else {
    std::printf("%s override %g %%\n", args[1].c_str(), 100.0 * result.value("value", 0.0));
  }
  return kDone;
}

}  // namespace cncd::cncctl
