// Who may call what through cncd-web: the four roles, each including the one before, and the
// methods that also need the control lease. The lists of roles.cpp answer every question, so
// the checks, the error messages and `web.session`'s method list cannot disagree.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cncd::web {

// In increasing order of power: a role may do everything the ones before it may.
// (`operator` is a C++ keyword, hence the trailing underscore.)
enum class Role { observer, operator_, setter, admin };

// "observer", "operator", "setter", "admin".
std::string_view role_name(Role role);
// The role of that name (exact, lower case), nullopt for any other text.
std::optional<Role> parse_role(std::string_view name);
// "observer|operator|setter|admin", for usage and error messages.
std::string role_names();

// The pseudo-method of an upload (HTTP PUT /api/programs/NAME): checked like a method.
inline constexpr std::string_view kUploadMethod = "upload";

// True when `role` may call `method` (a daemon method, a web-only method or kUploadMethod).
// A method the table does not know is allowed to no role: a method added to the daemon later
// stays unreachable from the web until it is given a role here.
bool allowed(Role role, std::string_view method);
// The least role that may call `method`; nullopt when no role may (unknown method).
std::optional<Role> required_role(std::string_view method);
// True when `method` moves the machine and so needs the control lease (machine.home,
// jog.start, jog.increment, mdi.execute, program.run, program.step); stopping never does.
bool needs_lease(std::string_view method);
// Every method `role` may call, in table order.
std::vector<std::string> methods(Role role);

// "method X needs role Y; you are Z" (JSON-RPC error 1020's message).
std::string refusal_message(std::string_view method, Role role);

}  // namespace cncd::web
