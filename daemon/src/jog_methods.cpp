#include "jog_methods.hpp"

#include <cctype>
#include <cmath>

namespace cncd::daemon {

using nlohmann::json;

namespace {

RpcError jog_refused(const std::string& reason) {
  const bool busy = reason == "the machine is moving" || reason == "the machine is jogging";
  return RpcError(busy ? kBusy : kWrongState, reason);
}

// The "axis" parameter: one of the machine's axis letters.
int axis_param(const json& params, const config::MachineConfig& config) {
  if (!params.is_object()) throw RpcError(kInvalidParams, "params must be an object");
  const auto it = params.find("axis");
  if (it == params.end() || !it->is_string() || it->get<std::string>().size() != 1)
    throw RpcError(kInvalidParams, "\"axis\" must be an axis letter such as \"X\"");
  const char letter =
      static_cast<char>(std::toupper(static_cast<unsigned char>(it->get<std::string>()[0])));
  const int axis = config::axis_index(letter);
  if (axis < 0 || !config.axes[static_cast<std::size_t>(axis)].present)
    throw RpcError(kInvalidParams, std::string("the machine has no axis ") + letter);
  return axis;
}

double number_param(const json& params, const char* name, bool required, double fallback) {
  const auto it = params.find(name);
  if (it == params.end() || it->is_null()) {
    if (required) throw RpcError(kInvalidParams, std::string("\"") + name + "\" is missing");
    return fallback;
  }
  if (!it->is_number() || !std::isfinite(it->get<double>()))
    throw RpcError(kInvalidParams, std::string("\"") + name + "\" must be a number");
  return it->get<double>();
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
    const double velocity = number_param(params, "velocity", true, 0);
    if (velocity == 0) throw RpcError(kInvalidParams, "\"velocity\" must not be 0");
    task.jog_start(axis, velocity);
    return ok();
  });
  dispatcher.add("jog.stop", [&task, &config](const json& params) {
    task.jog_stop(axis_param(params, config));
    return ok();
  });
  dispatcher.add("jog.increment", [&task, &config](const json& params) {
    const int axis = axis_param(params, config);
    const double distance = number_param(params, "distance", true, 0);
    if (distance == 0) throw RpcError(kInvalidParams, "\"distance\" must not be 0");
    // Without a velocity, the axis's MAX_VELOCITY.
    const double velocity = number_param(params, "velocity", false,
                                         config.axes[static_cast<std::size_t>(axis)].max_velocity);
    if (velocity <= 0) throw RpcError(kInvalidParams, "\"velocity\" must be above 0");
    task.jog_increment(axis, distance, velocity);
    return ok();
  });
}

}  // namespace cncd::daemon
