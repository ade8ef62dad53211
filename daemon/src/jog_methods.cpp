#include "jog_methods.hpp"

#include <cctype>

namespace cncd::daemon {

using nlohmann::json;

namespace {

// The "axis" parameter: one of the machine's axis letters; or "joint", one of its joints
// (motion::kJointJogBase + its number). `required`: one of the two must be there.
int axis_param(const json& params, const config::MachineConfig& config, bool required = true) {
  if (params.contains("joint")) {
    if (params.contains("axis"))
      throw RpcError(kInvalidParams, "give \"axis\" or \"joint\", not both");
    const int joint = params["joint"].get<int>();
    if (joint < 0 || static_cast<std::size_t>(joint) >= config.joints.size()) {
      throw RpcError(kInvalidParams, "parameter \"joint\": the machine has no joint " +
                                         std::to_string(joint) + " (it has " +
                                         std::to_string(config.joints.size()) + ")");
    }
    return motion::kJointJogBase + joint;
  }
  if (!params.contains("axis")) {
    if (!required) return -1;
    throw RpcError(kInvalidParams, "parameter \"axis\" or \"joint\" is required");
  }
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
                          const config::MachineConfig& config, JogHeartbeats& heartbeats,
                          const EventLog& events) {
  dispatcher.add("jog.start",
                 [&task, &config, &heartbeats, &events](const json& params, Session& session) {
                   const int axis = axis_param(params, config);
                   const double velocity = params["velocity"].get<double>();
                   if (velocity == 0)
                     throw RpcError(kInvalidParams, "parameter \"velocity\" must not be 0");
                   task.jog_start(axis, velocity);
                   heartbeats.started(axis, session.connection, params.value("heartbeat_s", 0.0),
                                      events.actor().empty() ? session.peer : events.actor(),
                                      JogHeartbeats::Clock::now());
                   return ok();
                 });
  dispatcher.add("jog.stop", [&task, &config, &heartbeats](const json& params) {
    const int axis = axis_param(params, config);
    heartbeats.forget(axis);
    task.jog_stop(axis);
    return ok();
  });
  dispatcher.add("jog.heartbeat", [&config, &heartbeats](const json& params, Session& session) {
    const int axis = axis_param(params, config, false);
    json axes = json::array();
    json joints = json::array();
    for (const int kept : heartbeats.beat(session.connection, axis, JogHeartbeats::Clock::now())) {
      if (kept >= motion::kJointJogBase)
        joints.push_back(kept - motion::kJointJogBase);
      else
        axes.push_back(jog_target_name(kept));
    }
    return json{{"ok", true}, {"axes", axes}, {"joints", joints}};
  });
  dispatcher.add("jog.increment", [&task, &config, &heartbeats](const json& params) {
    const int axis = axis_param(params, config);
    const double distance = params["distance"].get<double>();
    if (distance == 0) throw RpcError(kInvalidParams, "parameter \"distance\" must not be 0");
    // Without a velocity, the axis's (joint's) MAX_VELOCITY.
    const double velocity = params.value(
        "velocity",
        axis >= motion::kJointJogBase
            ? config.joints[static_cast<std::size_t>(axis - motion::kJointJogBase)].max_velocity
            : config.axes[static_cast<std::size_t>(axis)].max_velocity);
    if (velocity <= 0) throw RpcError(kInvalidParams, "parameter \"velocity\" must be above 0");
    task.jog_increment(axis, distance, velocity);
    heartbeats.forget(axis);
    return ok();
  });
}

}  // namespace cncd::daemon
