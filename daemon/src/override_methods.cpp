#include "override_methods.hpp"

namespace cncd::daemon {

using nlohmann::json;

namespace {

json applied(double ratio) {
  return json{{"value", ratio}};
}

}  // namespace

// The table declares "value" a number; its range comes from the configuration. A value outside
// it is refused naming the range, never clamped into it.
void register_override_methods(RpcDispatcher& dispatcher, Task& task,
                               const config::MachineConfig& config) {
  dispatcher.add("override.feed",
                 [&task](const json& params) {
                   const double ratio = params["value"].get<double>();
                   task.set_feed_override(ratio);
                   return applied(ratio);
                 },
                 {{"value", 0.0, config.max_feed_override}});
  dispatcher.add("override.rapid", [&task](const json& params) {
    const double ratio = params["value"].get<double>();
    task.set_rapid_override(ratio);
    return applied(ratio);
  });
  dispatcher.add("override.spindle",
                 [&task](const json& params) {
                   const double ratio = params["value"].get<double>();
                   task.set_spindle_override(ratio);
                   return applied(ratio);
                 },
                 {{"value", config.min_spindle_override, config.max_spindle_override}});
}

}  // namespace cncd::daemon
