#include "methods.hpp"

#include <filesystem>
#include <string>
#include <vector>

#include "jog_methods.hpp"
#include "override_methods.hpp"
#include "server.hpp"
#include "setup_methods.hpp"
#include "version.hpp"

namespace cncd::daemon {

using nlohmann::json;

namespace {

json ok() {
  return json{{"ok", true}};
}

const json& params_object(const json& params) {
  static const json empty = json::object();
  if (params.is_null()) return empty;
  if (!params.is_object()) throw RpcError(kInvalidParams, "params must be an object");
  return params;
}

// The optional "fields" list of status.get / status.subscribe; empty = every field.
std::vector<std::string> field_list(const json& params) {
  std::vector<std::string> fields;
  if (!params.is_object()) return fields;
  const auto it = params.find("fields");
  if (it == params.end() || it->is_null()) return fields;
  if (!it->is_array()) throw RpcError(kInvalidParams, "\"fields\" must be an array of names");
  for (const auto& f : *it) {
    if (!f.is_string()) throw RpcError(kInvalidParams, "\"fields\" must be an array of names");
    fields.push_back(f.get<std::string>());
  }
  return fields;
}

std::uint32_t joint_mask(const json& params, int joint_count) {
  const json& p = params_object(params);
  const auto joints = p.find("joints");
  if (joints == p.end() || joints->is_null()) return 0xFFFFFFFFu;
  if (!joints->is_array()) throw RpcError(kInvalidParams, "\"joints\" must be an array of numbers");
  std::uint32_t mask = 0;
  for (const auto& j : *joints) {
    // As a 64-bit number: 4294967296 must not wrap to joint 0.
    if (!j.is_number_integer() || j.get<std::int64_t>() < 0 ||
        j.get<std::int64_t>() >= joint_count) {
      throw RpcError(kInvalidParams, "\"joints\" holds an unknown joint: " + j.dump());
    }
    mask |= 1u << j.get<std::int64_t>();
  }
  return mask;
}

}  // namespace

void register_methods(RpcDispatcher& dispatcher, Task& task, const config::MachineConfig& config,
                      const EventLog& events, Completions& completions) {
  dispatcher.add(
      "errors.list",
      [&events](const json& params) {
        const json& p = params_object(params);
        const auto since = p.value("since", std::uint64_t{0});
        return json{{"last_seq", events.last_seq()}, {"events", events.since(since)}};
      },
      Access::read);
  dispatcher.add(
      "system.info",
      [&config](const json&) {
        json axes = json::array();
        for (std::size_t i = 0; i < config::kAxisLetters.size(); ++i) {
          if (config.axes[i].present) axes.push_back(std::string(1, config::kAxisLetters[i]));
        }
        json drivers = json::array();
        for (const auto& joint : config.joints)
          drivers.push_back(joint.driver);
        return json{{"version", kVersion},
                    {"protocol_version", kProtocolVersion},
                    {"machine",
                     {{"name", config.machine_name},
                      {"config", config.path.string()},
                      {"units", config.linear_units == config::LinearUnits::inch ? "inch" : "mm"},
                      {"axes", axes},
                      {"joints", config.joints.size()},
                      {"drivers", drivers},
                      {"servo_period_ns", config.servo_period_ns}}}};
      },
      Access::read);
  dispatcher.add(
      "status.get",
      [&task](const json& params) {
        const auto fields = field_list(params);
        const json status = task.status();
        if (fields.empty()) return status;
        json out = json::object();
        for (const auto& f : fields) {
          if (!status.contains(f)) throw RpcError(kInvalidParams, "unknown field '" + f + "'");
          out[f] = status[f];
        }
        return out;
      },
      Access::read);
  dispatcher.add(
      "status.subscribe",
      [&task](const json& params, Session& session) {
        const json& p = params_object(params);
        const int interval = p.value("interval_ms", 100);
        if (interval < Server::kMinSubscribeIntervalMs || interval > 3'600'000) {
          throw RpcError(kInvalidParams, "\"interval_ms\" must be from 10 to 3600000");
        }
        const auto fields = field_list(params);
        for (const auto& f : fields) {
          if (!task.status().contains(f))
            throw RpcError(kInvalidParams, "unknown field '" + f + "'");
        }
        session.subscribe_interval_ms = interval;
        session.fields = fields;
        return json{{"interval_ms", interval}, {"fields", fields}};
      },
      Access::read);
  dispatcher.add(
      "status.unsubscribe",
      [](const json&, Session& session) {
        session.subscribe_interval_ms = 0;
        session.fields.clear();
        return ok();
      },
      Access::read);
  dispatcher.add("machine.estop", [&task](const json&) {
    task.estop();
    return ok();
  });
  dispatcher.add("machine.reset", [&task](const json&) {
    task.reset();
    return ok();
  });
  dispatcher.add("machine.on", [&task](const json&) {
    task.machine_on();
    return ok();
  });
  dispatcher.add("machine.off", [&task](const json&) {
    task.machine_off();
    return ok();
  });
  const int joint_count = static_cast<int>(config.joints.size());
  dispatcher.add("machine.home", [&task, joint_count](const json& params) {
    task.home(joint_mask(params, joint_count));
    return ok();
  });
  dispatcher.add("program.open", [&task](const json& params) {
    const json& p = params_object(params);
    const auto path = p.find("path");
    if (path == p.end() || !path->is_string() || path->get<std::string>().empty()) {
      throw RpcError(kInvalidParams, "\"path\" must be a non-empty string");
    }
    task.open_program(path->get<std::string>());
    return json{{"path", path->get<std::string>()}};
  });
  dispatcher.add("program.run", [&task](const json& params) {
    const json& p = params_object(params);
    int from_line = 0;
    if (const auto it = p.find("from_line"); it != p.end() && !it->is_null()) {
      if (!it->is_number_integer() || it->get<std::int64_t>() < 1 ||
          it->get<std::int64_t>() > 100'000'000) {
        throw RpcError(kInvalidParams, "\"from_line\" must be a line number from 1");
      }
      from_line = it->get<int>();
    }
    task.run_program(from_line);
    return ok();
  });
  dispatcher.add("program.step", [&task](const json&) {
    task.step();
    return ok();
  });
  dispatcher.add("program.pause", [&task](const json&) {
    task.pause();
    return ok();
  });
  dispatcher.add("program.resume", [&task](const json&) {
    task.resume();
    return ok();
  });
  dispatcher.add("program.abort", [&task, &completions](const json&, Session& session) {
    if (session.in_batch) {
      task.abort();
      return ok();
    }
    const auto token = completions.next_token();
    task.abort(token);
    session.defer_token = token;
    return json();
  });
  dispatcher.add("mdi.execute", [&task, &completions](const json& params, Session& session) {
    if (session.in_batch) throw RpcError(kInvalidRequest, "mdi.execute cannot be part of a batch");
    const json& p = params_object(params);
    const auto line = p.find("line");
    if (line == p.end() || !line->is_string()) {
      throw RpcError(kInvalidParams, "\"line\" must be a string");
    }
    const auto token = completions.next_token();
    task.mdi(line->get<std::string>(), token);
    session.defer_token = token;
    return json();
  });
  register_setup_methods(dispatcher, task, config);
  register_jog_methods(dispatcher, task, config);
  register_override_methods(dispatcher, task, config);
}

}  // namespace cncd::daemon
