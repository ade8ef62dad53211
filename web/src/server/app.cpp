#include "app.hpp"

#include <algorithm>
#include <cctype>

#include <spdlog/spdlog.h>

#include "http_common.hpp"

namespace cncd::web {
config::MachineConfig with_web_defaults(config::MachineConfig machine) {
  if (machine.web.program_dir.empty() && !machine.program_dirs.empty())
    machine.web.program_dir = machine.program_dirs.front();
  if (machine.web.users_file.empty() && !machine.cncd.state_dir.empty())
    machine.web.users_file = machine.cncd.state_dir / "web-users";
  return machine;
}

namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

// The value of cookie `name` in a Cookie header ("a=1; b=2").
std::string_view cookie_value(std::string_view header, std::string_view name) {
  while (!header.empty()) {
    const auto end = header.find(';');
    auto item = header.substr(0, end);
    while (!item.empty() && item.front() == ' ')
      item.remove_prefix(1);
    if (item.size() > name.size() && item.starts_with(name) && item[name.size()] == '=')
      return item.substr(name.size() + 1);
    header = end == std::string_view::npos ? std::string_view() : header.substr(end + 1);
  }
  return {};
}

}  // namespace

App::App(boost::asio::io_context& io_context, config::MachineConfig machine_config,
         const std::filesystem::path& check)
    : io(io_context),
      machine(with_web_defaults(std::move(machine_config))),
      web(machine.web),
      socket_path(machine.cncd.socket_path),
      users(web.users_file),
      dummy_hash(hash_password("no such user: the same work as a wrong password")),
      sessions(std::chrono::hours(web.session_hours)),
      programs(web.program_dir, web.max_upload_bytes),
      estimates(check, machine.path) {
  lease.set_observer([this](const std::optional<LeaseHolder>& holder, std::uint64_t) {
    broadcast(nlohmann::json{
        {"jsonrpc", "2.0"}, {"method", "lease.changed"}, {"params", lease_holder_json(holder)}}
                  .dump());
  });
}

std::string App::refresh_users() {
  if (!users.changed_on_disk()) return "";
  return users.load();
}

std::optional<Identity> App::identify(std::string_view cookie, std::string_view authorization) {
  if (const auto token = cookie_value(cookie, "cncd_session"); !token.empty()) {
    if (auto session = sessions.find(token)) {
      return Identity{session->user, session->role, *session, false};
    }
  }
  if (authorization.size() > 7 && lower(authorization.substr(0, 7)) == "bearer ") {
    if (const auto problem = refresh_users(); !problem.empty()) spdlog::error("{}", problem);
    const User* user = users.check_key(authorization.substr(7));
    if (user == nullptr) return std::nullopt;
    auto found = key_sessions.find(user->name);
    if (found == key_sessions.end() || found->second.role != user->role ||
        !sessions.find_id(found->second.id)) {
      // A session of its own for the key's user, so that a WebSocket on a key can hold the
      // lease like one on a cookie; its token is never handed out.
      found = key_sessions
                  .insert_or_assign(user->name, sessions.create(user->name, user->role, "api-key"))
                  .first;
    }
    return Identity{user->name, user->role, found->second, true};
  }
  return std::nullopt;
}

void App::broadcast(const std::string& text) {
  for (auto* peer : peers)
    peer->notify(text);
}

void App::sessions_dropped(const std::vector<std::string>& ids) {
  for (const auto& id : ids) {
    lease.session_closed(id);
    std::vector<WsPeer*> closing;
    for (auto* peer : peers) {
      if (peer->session_id() == id) closing.push_back(peer);
    }
    for (auto* peer : closing)
      peer->close_with("the session ended");
  }
}

nlohmann::json App::lease_json() const {
  return lease_holder_json(lease.holder());
}

bool App::origin_allowed(std::string_view origin, std::string_view host, bool secure) const {
  return web::origin_allowed(origin, host, secure, web.allowed_origins);
}

nlohmann::json lease_holder_json(const std::optional<LeaseHolder>& holder) {
  if (!holder) return nullptr;
  return {{"user", holder->user},
          {"address", holder->address},
          {"since", std::chrono::duration<double>(holder->since.time_since_epoch()).count()}};
}

}  // namespace cncd::web
