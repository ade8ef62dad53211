#include "cncd/web/roles.hpp"

#include <algorithm>
#include <array>
#include <span>

namespace cncd::web {
namespace {

// The methods each role gains over the one before, in the order methods() lists them.
// Stopping is open to everyone logged in (machine.estop is an observer's; pause, abort,
// jog.stop need no lease), so a second person at the machine can always stop it.
constexpr std::string_view kObserverMethods[] = {
    "status.get",  "status.subscribe", "status.unsubscribe", "errors.list",  "system.info",
    "tool.list",   "offsets.get",      "jobs.history",       "jobs.stats",   "program.preview",
    "web.session", "lease.get",        "files.list",         "machine.estop"};
constexpr std::string_view kOperatorMethods[] = {
    "machine.reset", "machine.on",    "machine.off",    "machine.home",     "jog.start",
    "jog.stop",      "jog.increment", "jog.heartbeat",  "program.open",     "files.open",
    "program.run",   "program.step",  "program.pause",  "program.resume",   "program.abort",
    "mdi.execute",   "override.feed", "override.rapid", "override.spindle", "tool.change_done",
    "wait.done",     "lease.take",    "lease.release"};
constexpr std::string_view kSetterMethods[] = {"tool.set", "offsets.set", "files.rename",
                                               "files.delete", kUploadMethod};
constexpr std::string_view kAdminMethods[] = {"users.list", "users.add", "users.delete",
                                              "users.passwd"};

struct RoleMethods {
  Role role;
  std::span<const std::string_view> methods;
};
constexpr RoleMethods kByRole[] = {{Role::observer, kObserverMethods},
                                   {Role::operator_, kOperatorMethods},
                                   {Role::setter, kSetterMethods},
                                   {Role::admin, kAdminMethods}};

// The operator's methods that move the machine: only for the lease's holder.
constexpr std::string_view kLeaseMethods[] = {"machine.home", "jog.start",    "jog.increment",
                                              "program.run",  "program.step", "mdi.execute"};

constexpr std::array<std::string_view, 4> kRoleNames{"observer", "operator", "setter", "admin"};

constexpr bool listed(std::span<const std::string_view> list, std::string_view method) {
  return std::ranges::find(list, method) != list.end();
}
static_assert(std::ranges::all_of(kLeaseMethods, [](std::string_view method) {
  return listed(kOperatorMethods, method);
}));

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
  const auto needed = required_role(method);
  return needed && role >= *needed;
}

std::optional<Role> required_role(std::string_view method) {
  for (const auto& [role, list] : kByRole) {
    if (listed(list, method)) return role;
  }
  return std::nullopt;
}

bool needs_lease(std::string_view method) {
  return listed(kLeaseMethods, method);
}

std::vector<std::string> methods(Role role) {
  std::vector<std::string> out;
  for (const auto& [least, list] : kByRole) {
    if (role >= least) out.insert(out.end(), list.begin(), list.end());
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
