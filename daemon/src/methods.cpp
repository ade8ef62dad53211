#include "methods.hpp"

#include <filesystem>
#include <string>
#include <vector>

#include "jog_methods.hpp"
#include "override_methods.hpp"
#include "server.hpp"
#include "setup_methods.hpp"
#include "sim_methods.hpp"
#include "status_json.hpp"
#include "version.hpp"

namespace cncd::daemon {

using nlohmann::json;

namespace {

json ok() {
  return json{{"ok", true}};
}

// The "fields" list of status.get / status.subscribe; empty = every field.
std::vector<std::string> field_list(const json& params) {
  if (!params.contains("fields")) return {};
  return params["fields"].get<std::vector<std::string>>();
}

void check_fields(const std::vector<std::string>& fields, const json& status) {
  for (const auto& f : fields) {
    if (!status.contains(f)) {
      throw RpcError(kInvalidParams,
                     "parameter \"fields\": unknown status field " + quoted_text(f));
    }
  }
}

std::uint32_t joint_mask(const json& params) {
  if (!params.contains("joints")) return 0xFFFFFFFFu;
  std::uint32_t mask = 0;
  for (const auto& j : params["joints"])
    mask |= 1u << j.get<int>();
  return mask;
}

// A method without parameters that hands one command to the task and answers ok.
void add_command(RpcDispatcher& dispatcher, Task& task, const char* method,
                 void (Task::*command)()) {
  dispatcher.add(method, [&task, command](const json&) {
    (task.*command)();
    return ok();
  });
}

}  // namespace

void register_methods(RpcDispatcher& dispatcher, Task& task, const config::MachineConfig& config,
                      const EventLog& events, Completions& completions, JogHeartbeats& heartbeats,
                      StatusCache* shared_status) {
  dispatcher.add("errors.list", [&events](const json& params) {
    const auto since = params.value("since", std::uint64_t{0});
    return json{{"last_seq", events.last_seq()}, {"events", events_json(events.since(since))}};
  });
  // Read on the job history's thread: a slow disk does not hold up the loop.
  for (const bool stats : {false, true}) {
    dispatcher.add(stats ? "jobs.stats" : "jobs.history",
                   [&task, &completions, stats](const json& params, Session& session) {
                     if (session.in_batch) {
                       throw RpcError(kInvalidRequest, "the job history cannot be read in a batch");
                     }
                     const auto token = completions.next_token();
                     task.ask_jobs(token, stats, params.value("since", 0.0),
                                   params.value("limit", 100));
                     session.defer_token = token;
                     return json();
                   });
  }
  dispatcher.add("system.info", [&config](const json&) {
    json axes = json::array();
    json limits = json::object();
    for (std::size_t i = 0; i < config::kAxisLetters.size(); ++i) {
      if (!config.axes[i].present) continue;
      const std::string letter(1, config::kAxisLetters[i]);
      axes.push_back(letter);
      limits[std::string(1, static_cast<char>(config::kAxisLetters[i] - 'A' + 'a'))] = {
          config.axes[i].min_limit, config.axes[i].max_limit};
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
                  {"kinematics", config.kinematics},
                  {"drivers", drivers},
                  {"servo_period_ns", config.servo_period_ns},
                  {"soft_limits", limits},
                  {"overrides",
                   {{"max_feed", config.max_feed_override},
                    {"min_spindle", config.min_spindle_override},
                    {"max_spindle", config.max_spindle_override}}}}}};
  });
  const auto selected = [](const json& params, const json& status) {
    const auto fields = field_list(params);
    check_fields(fields, status);
    json out = json::object();
    for (const auto& f : fields)
      out[f] = status[f];
    return out;
  };
  if (shared_status != nullptr) {
    dispatcher.add_raw("status.get", [selected, cache = shared_status](const json& params,
                                                                       Session&) {
      if (!params.contains("fields") || params["fields"].empty()) return cache->text();
      return selected(params, cache->get()).dump(-1, ' ', false, json::error_handler_t::replace);
    });
  } else {
    // Without a status cache there is no server (the fuzz harness): nobody is connected.
    dispatcher.add("status.get", [selected, &task, &config](const json& params) {
      const json status = status_json(task.status(), config, 0);
      return field_list(params).empty() ? status : selected(params, status);
    });
  }
  dispatcher.add("status.subscribe",
                 [&task, &config](const json& params, Session& session) {
                   const int interval = params.value("interval_ms", 100);
                   const auto fields = field_list(params);
                   check_fields(fields, status_json(task.status(), config, 0));
                   session.subscribe_interval_ms = interval;
                   session.fields = fields;
                   return json{{"interval_ms", interval}, {"fields", fields}};
                 },
                 {{"interval_ms", Server::kMinSubscribeIntervalMs, 3'600'000}});
  dispatcher.add("status.unsubscribe", [](const json&, Session& session) {
    session.subscribe_interval_ms = 0;
    session.fields.clear();
    return ok();
  });
  add_command(dispatcher, task, "machine.estop", &Task::estop);
  add_command(dispatcher, task, "machine.reset", &Task::reset);
  dispatcher.add("machine.on", [&task, &completions](const json&, Session& session) {
    // Answered once the drives have had the time to report a fault; a batch waits for it.
    const auto token = session.in_batch ? 0 : completions.next_token();
    if (!task.machine_on(token)) return ok();
    session.defer_token = token;
    return json();
  });
  add_command(dispatcher, task, "machine.off", &Task::machine_off);
  const double last_joint = static_cast<double>(config.joints.size()) - 1;
  dispatcher.add("machine.home",
                 [&task](const json& params) {
                   task.home(joint_mask(params));
                   return ok();
                 },
                 {{"joints", 0, last_joint}});
  // Answered once the program has been checked, on a worker thread: the loop serves others
  // meanwhile.
  dispatcher.add("program.open", [&task, &completions](const json& params, Session& session) {
    if (session.in_batch) throw RpcError(kInvalidRequest, "program.open cannot be part of a batch");
    const auto path = params["path"].get<std::string>();
    if (path.empty()) throw RpcError(kInvalidParams, "parameter \"path\" must not be empty");
    // The system calls would see the path end there: another file than the one named.
    if (path.find('\0') != std::string::npos) {
      throw RpcError(kInvalidParams, "parameter \"path\" must not contain a NUL character");
    }
    const auto token = completions.next_token();
    task.open_program(path, token);
    session.defer_token = token;
    return json();
  });
  // Answered once worked out on a worker thread, or at once when kept from an earlier ask.
  dispatcher.add("program.preview", [&task, &completions](const json& params, Session& session) {
    if (session.in_batch) {
      throw RpcError(kInvalidRequest, "program.preview cannot be part of a batch");
    }
    const auto token = completions.next_token();
    task.preview_program(params.value("tolerance", 0.0), token);
    session.defer_token = token;
    return json();
  });
  dispatcher.add("program.run", [&task](const json& params) {
    // 0: from the top.
    task.run_program(params.value("from_line", 0));
    return ok();
  });
  add_command(dispatcher, task, "program.step", &Task::step);
  dispatcher.add("program.pause", [&task](const json&) {
    const PauseWaitReport wait = task.pause();
    json answer = ok();
    if (!wait.kind.empty()) {
      answer["waits_for"] = wait.kind;
      answer["line"] = wait.line;
      answer["message"] = wait.message;
    }
    return answer;
  });
  add_command(dispatcher, task, "program.resume", &Task::resume);
  dispatcher.add("tool.change_done", [&task](const json& params) {
    task.tool_change_done(params["tool"].get<int>());
    return ok();
  });
  dispatcher.add("wait.done", [&task](const json& params) {
    task.wait_done(params["kind"].get<std::string>());
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
    const auto token = completions.next_token();
    task.mdi(params["line"].get<std::string>(), token);
    session.defer_token = token;
    return json();
  });
  register_setup_methods(dispatcher, task, config);
  register_jog_methods(dispatcher, task, config, heartbeats, events);
  register_override_methods(dispatcher, task, config);
  register_sim_methods(dispatcher, task, config);
  dispatcher.require_all_added();
}

}  // namespace cncd::daemon
