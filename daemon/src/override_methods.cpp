#include "override_methods.hpp"

#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace cncd::daemon {

using nlohmann::json;

namespace {

// "1.5 (150 %)"
std::string ratio_text(double ratio) {
  return fmt::format("{:g} ({:g} %)", ratio, ratio * 100.0);
}

json applied(double ratio) {
  return json{{"value", ratio}};
}

}  // namespace

void Task::set_feed_override(double ratio) {
  motion_.set_feed_override(ratio);
  spdlog::debug("feed override {}", ratio_text(ratio));
}

void Task::set_rapid_override(double ratio) {
  motion_.set_rapid_override(ratio);
  spdlog::debug("rapid override {}", ratio_text(ratio));
}

void Task::set_spindle_override(double ratio) {
  spindle_override_ = ratio;
  spdlog::debug("spindle override {}", ratio_text(ratio));
}

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
