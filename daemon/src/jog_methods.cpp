#include "jog_methods.hpp"

#include <cctype>

namespace cncd::daemon {

using nlohmann::json;

namespace {

// The "axis" parameter: one of the machine's axis letters.
int axis_param(const json& params, const config::MachineConfig& config) {
  const auto& name = params["axis"].get_ref<const std::string&>();
  const int axis =
      name.size() == 1
          ? config::axis_index(static_cast<char>(std::toupper(static_cast<unsigned char>(name[0]))))
          : -1;
  if (axis < 0 || !config.axes[static_cast<std::size_t>(axis)].present) {
    throw RpcError(kInvalidParams,
                   "parameter \"axis\": the machine has no axis " + quoted_text(name));
  }
  return axis;
}

json ok() {
  return json{{"ok", true}};
}

}  // namespace

void register_jog_methods(RpcDispatcher& dispatcher, Task& task,
                          const config::MachineConfig& config) {
  dispatcher.add("jog.start", [&task, &config](const json& params) {
    const int axis = axis_param(params, config);
    const double velocity = params["velocity"].get<double>();
    if (velocity == 0) throw RpcError(kInvalidParams, "parameter \"velocity\" must not be 0");
    task.jog_start(axis, velocity);
    return ok();
  });
  dispatcher.add("jog.stop", [&task, &config](const json& params) {
    task.jog_stop(axis_param(params, config));
    return ok();
  });
  dispatcher.add("jog.increment", [&task, &config](const json& params) {
    const int axis = axis_param(params, config);
    const double distance = params["distance"].get<double>();
    if (distance == 0) throw RpcError(kInvalidParams, "parameter \"distance\" must not be 0");
    // Without a velocity, the axis's MAX_VELOCITY.
    const double velocity =
        params.value("velocity", config.axes[static_cast<std::size_t>(axis)].max_velocity);
    if (velocity <= 0) throw RpcError(kInvalidParams, "parameter \"velocity\" must be above 0");
    task.jog_increment(axis, distance, velocity);
    return ok();
  });
}

}  // namespace cncd::daemon
