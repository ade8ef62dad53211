#include "jog_methods.hpp"

#include <cctype>

namespace cncd::daemon {

using nlohmann::json;

namespace {

RpcError jog_refused(const std::string& reason) {
  const bool busy = reason == "the machine is moving" || reason == "the machine is jogging";
  return RpcError(busy ? kBusy : kWrongState, reason);
}

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

void Task::jog_start(int axis, double velocity) {
  if (exec_ != ExecState::idle) throw RpcError(kBusy, "a program or MDI block is running");
  if (const auto error = motion_.jog_start(axis, velocity); !error.empty())
    throw jog_refused(error);
}

void Task::jog_increment(int axis, double distance, double velocity) {
  if (exec_ != ExecState::idle) throw RpcError(kBusy, "a program or MDI block is running");
  if (const auto error = motion_.jog_increment(axis, distance, velocity); !error.empty())
    throw jog_refused(error);
}

void Task::jog_stop(int axis) {
  motion_.jog_stop(axis);
}

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
