#include "override_methods.hpp"

#include <cmath>
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

// The "value" parameter: a ratio from `min` to `max`. Anything else is refused naming the range;
// a value just outside it is never clamped into it.
double ratio_param(const json& params, const char* what, double min, double max) {
  const std::string range =
      fmt::format("\"value\" must be a number from {:g} to {:g} ({} override ratio, 1.0 = 100 %)",
                  min, max, what);
  if (!params.is_object()) throw RpcError(kInvalidParams, "params must be an object; " + range);
  const auto it = params.find("value");
  if (it == params.end() || !it->is_number()) throw RpcError(kInvalidParams, range);
  const double value = it->get<double>();
  if (!std::isfinite(value) || value < min || value > max) {
    throw RpcError(kInvalidParams, range + ", not " + it->dump());
  }
  return value;
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

void register_override_methods(RpcDispatcher& dispatcher, Task& task,
                               const config::MachineConfig& config) {
  dispatcher.add("override.feed", [&task, &config](const json& params) {
    const double ratio = ratio_param(params, "feed", 0.0, config.max_feed_override);
    task.set_feed_override(ratio);
    return applied(ratio);
  });
  dispatcher.add("override.rapid", [&task](const json& params) {
    const double ratio = ratio_param(params, "rapid", 0.0, 1.0);
    task.set_rapid_override(ratio);
    return applied(ratio);
  });
  dispatcher.add("override.spindle", [&task, &config](const json& params) {
    const double ratio =
        ratio_param(params, "spindle", config.min_spindle_override, config.max_spindle_override);
    task.set_spindle_override(ratio);
    return applied(ratio);
  });
}

}  // namespace cncd::daemon
