#include "cncd/web/roles.hpp"

#include <array>

namespace cncd::web {
namespace {

struct MethodRule {
  std::string_view method;  // a trailing ".*" covers every method of that prefix
  Role role;                // the least role that may call it
  bool lease = false;       // moves the machine: only for the lease's holder
};

// Stopping is open to everyone logged in (machine.estop is an observer's; pause, abort,
// jog.stop need no lease), so a second person at the machine can always stop it.
constexpr std::array kRules{
    MethodRule{"status.get", Role::observer},
    MethodRule{"status.subscribe", Role::observer},
    MethodRule{"status.unsubscribe", Role::observer},
    MethodRule{"errors.list", Role::observer},
    MethodRule{"system.info", Role::observer},
    MethodRule{"tool.list", Role::observer},
    MethodRule{"offsets.get", Role::observer},
    MethodRule{"jobs.history", Role::observer},
    MethodRule{"jobs.stats", Role::observer},
    MethodRule{"program.preview", Role::observer},
    MethodRule{"web.session", Role::observer},
    MethodRule{"lease.get", Role::observer},
    MethodRule{"files.list", Role::observer},
    MethodRule{"machine.estop", Role::observer},
    MethodRule{"machine.reset", Role::operator_},
    MethodRule{"machine.on", Role::operator_},
    MethodRule{"machine.off", Role::operator_},
    MethodRule{"machine.home", Role::operator_, true},
    MethodRule{"jog.start", Role::operator_, true},
    MethodRule{"jog.stop", Role::operator_},
    MethodRule{"jog.increment", Role::operator_, true},
    MethodRule{"jog.heartbeat", Role::operator_},
    MethodRule{"program.open", Role::operator_},
    MethodRule{"files.open", Role::operator_},
    MethodRule{"program.run", Role::operator_, true},
    MethodRule{"program.step", Role::operator_, true},
    MethodRule{"program.pause", Role::operator_},
    MethodRule{"program.resume", Role::operator_},
    MethodRule{"program.abort", Role::operator_},
    MethodRule{"mdi.execute", Role::operator_, true},
    MethodRule{"override.feed", Role::operator_},
    MethodRule{"override.rapid", Role::operator_},
    MethodRule{"override.spindle", Role::operator_},
    MethodRule{"tool.change_done", Role::operator_},
    MethodRule{"wait.done", Role::operator_},
    MethodRule{"lease.take", Role::operator_},
    MethodRule{"lease.release", Role::operator_},
    MethodRule{"tool.set", Role::setter},
    MethodRule{"offsets.set", Role::setter},
    MethodRule{"files.rename", Role::setter},
    MethodRule{"files.delete", Role::setter},
    MethodRule{kUploadMethod, Role::setter},
    MethodRule{"users.list", Role::admin},
    MethodRule{"users.add", Role::admin},
    MethodRule{"users.delete", Role::admin},
    MethodRule{"users.passwd", Role::admin},
};

constexpr std::array<std::string_view, 4> kRoleNames{"observer", "operator", "setter", "admin"};

const MethodRule* rule(std::string_view method) {
  for (const auto& r : kRules) {
    if (r.method == method) return &r;
  }
  return nullptr;
}

}  // namespace

std::string_view role_name(Role role) {
  return kRoleNames[static_cast<std::size_t>(role)];
}

std::optional<Role> parse_role(std::string_view name) {
  for (std::size_t i = 0; i < kRoleNames.size(); ++i) {
    if (kRoleNames[i] == name) return static_cast<Role>(i);
  }
  return std::nullopt;
}

std::string role_names() {
  std::string out;
  for (const auto name : kRoleNames) {
    if (!out.empty()) out += '|';
    out += name;
  }
  return out;
}

bool allowed(Role role, std::string_view method) {
  const MethodRule* r = rule(method);
  return r != nullptr && role >= r->role;
}

std::optional<Role> required_role(std::string_view method) {
  const MethodRule* r = rule(method);
  if (r == nullptr) return std::nullopt;
  return r->role;
}

bool needs_lease(std::string_view method) {
  const MethodRule* r = rule(method);
  return r != nullptr && r->lease;
}

std::vector<std::string> methods(Role role) {
  std::vector<std::string> out;
  for (const auto& r : kRules) {
    if (role >= r.role) out.emplace_back(r.method);
  }
  return out;
}

std::string refusal_message(std::string_view method, Role role) {
  const auto needed = required_role(method);
  if (!needed) {
    return "method " + std::string(method) + " is not available through cncd-web";
  }
  return "method " + std::string(method) + " needs role " + std::string(role_name(*needed)) +
         "; you are " + std::string(role_name(role));
}

}  // namespace cncd::web
