// The methods cncd-web answers itself: the session, the control lease, the program files and
// the users. Their role was checked before (roles.hpp).
#include <spdlog/spdlog.h>

#include "ws_rpc.hpp"

namespace cncd::web {
namespace {

using json = nlohmann::json;

constexpr int kInvalidParams = -32602;
constexpr int kFileError = 1007;

// The string parameter `name`; WebError when missing or not a string.
std::string text_param(const json& params, const char* name, const std::string& method) {
  if (!params.is_object() || !params.value(name, json()).is_string())
    throw WebError{kInvalidParams, method + " needs \"" + name + "\", a string"};
  return params[name];
}

void check_file(const FileStatus& status) {
  if (!status.ok()) throw WebError{kFileError, status.message};
}

void save_users(App& app) {
  if (const auto problem = app.users.save(); !problem.empty()) {
    app.users.load();  // memory back to what the file holds
    throw WebError{kFileError, problem};
  }
}

void check_edit(App& app, const std::string& problem) {
  if (!problem.empty()) {
    app.users.load();
    throw WebError{kInvalidParams, problem};
  }
}

}  // namespace

json WsRpc::web_method(const std::string& method, const json& params, json& forward) {
  if (method == "web.session") {
    json methods = json::array();
    for (const auto& m : web::methods(who_.role))
      methods.push_back(m);
    return {{"user", who_.user},
            {"role", role_name(who_.role)},
            {"methods", methods},
            {"lease", app_.lease_json()},
            {"session", who_.session.id}};
  }
  if (method == "lease.get") return app_.lease_json();
  if (method == "lease.take") {
    const bool force = params.is_object() && params.value("force", false) == true;
    // One hand on the machine: while the panel at the machine jogs, control is not taken
    // from the web, forced or not.
    if (app_.manual_holder.is_object() && app_.manual_holder.value("panel", false) &&
        !app_.lease.held_by(who_.session.id)) {
      const auto axis = app_.manual_holder.value("axis", nlohmann::json());
      throw WebError{kLeaseRefused,
                     app_.manual_holder.value("by", std::string("the panel")) + " is jogging" +
                         (axis.is_string() ? " " + axis.get<std::string>() : std::string()) +
                         " at the machine: take control once it rests"};
    }
    Session session = who_.session;
    session.address = address_;
    const auto taken = app_.lease.take(session, force);
    if (!taken.ok) {
      const auto& h = taken.holder;
      throw WebError{kLeaseRefused, "the control lease is held by " +
                                        (h ? h->user + " at " + h->address : "") +
                                        "; take it over with {\"force\": true}"};
    }
    spdlog::info("{} at {} took the control lease{}", who_.user, address_,
                 force ? " (forced)" : "");
    return lease_holder_json(taken.holder);
  }
  if (method == "lease.release") return {{"released", app_.lease.release(who_.session.id)}};
  if (method == "files.list") {
    FileStatus status;
    const auto entries = app_.programs.list(status);
    check_file(status);
    json list = json::array();
    for (const auto& e : *entries) {
      const auto estimate = app_.estimates.get(app_.programs.path() / e.name, e.size, e.mtime);
      list.push_back({{"name", e.name},
                      {"size", e.size},
                      {"mtime", std::chrono::duration<double>(e.mtime.time_since_epoch()).count()},
                      {"estimate_s", estimate ? json(*estimate) : json()}});
    }
    return list;
  }
  if (method == "files.rename") {
    const auto from = text_param(params, "from", method);
    const auto to = text_param(params, "to", method);
    check_file(app_.programs.rename(from, to, app_.running()));
    spdlog::info("{} at {} renamed program {} to {}", who_.user, address_, from, to);
    return {{"ok", true}};
  }
  if (method == "files.delete") {
    const auto name = text_param(params, "name", method);
    check_file(app_.programs.remove(name, app_.running()));
    spdlog::info("{} at {} deleted program {}", who_.user, address_, name);
    return {{"ok", true}};
  }
  if (method == "files.open") {
    forward = {{"jsonrpc", "2.0"},
               {"method", "program.open"},
               {"params", {{"path", text_param(params, "name", method)}}}};
    return nullptr;
  }
  if (const auto problem = app_.refresh_users(); !problem.empty())
    throw WebError{kFileError, problem};
  if (method == "users.list") {
    json list = json::array();
    for (const auto& user : app_.users.users()) {
      json keys = json::array();
      for (const auto& key : user.keys)
        keys.push_back(key.id);
      list.push_back({{"name", user.name},
                      {"role", role_name(user.role)},
                      {"password", user.password_hash != "-"},
                      {"keys", keys}});
    }
    return list;
  }
  const auto name = text_param(params, "name", method);
  if (method == "users.add" || method == "users.passwd") {
    std::optional<Role> role;
    if (method == "users.add") {
      role = parse_role(text_param(params, "role", method));
      if (!role) throw WebError{kInvalidParams, "role must be one of " + role_names()};
      if (auto why = check_user_name(name); !why.empty()) throw WebError{kInvalidParams, why};
      if (app_.users.find(name) != nullptr)
        throw WebError{kInvalidParams, "user '" + name + "' exists already"};
    } else if (app_.users.find(name) == nullptr) {
      throw WebError{kInvalidParams, "no user '" + name + "'"};
    }
    const auto password = text_param(params, "password", method);
    if (auto why = check_password(password); !why.empty()) throw WebError{kInvalidParams, why};
    // argon2 takes a tenth of a second by design: hashed on a worker, never on the thread that
    // forwards every WebSocket's estops; the file is changed back on this thread.
    later_work_ = [password, cost = app_.users.cost()] { return hash_password(password, cost); };
    later_finish_ = [&app = app_, method, name, role, who = who_.user,
                     address = address_](std::string hash) -> json {
      if (const auto problem = app.refresh_users(); !problem.empty())
        throw WebError{kFileError, problem};
      check_edit(app, role ? app.users.add(name, *role, HashedPassword{std::move(hash)})
                           : app.users.set_password(name, HashedPassword{std::move(hash)}));
      save_users(app);
      if (!role) app.sessions_dropped(app.sessions.drop_user(name));
      spdlog::info("{} at {}: {} {}", who, address, method, name);
      return {{"ok", true}};
    };
    return nullptr;
  }
  if (method == "users.delete") {
    check_edit(app_, app_.users.remove(name));
    save_users(app_);
    app_.sessions_dropped(app_.sessions.drop_user(name));
  } else {
    throw WebError{-32601, "unknown method \"" + method + "\""};
  }
  spdlog::info("{} at {}: {} {}", who_.user, address_, method, name);
  return {{"ok", true}};
}

}  // namespace cncd::web
