// The "on_behalf_of" member of a request: a trusted front end (cncd-web) names the person and
// the address it serves, so that the event log says who did what rather than only which local
// process. Only a peer with control access may send it: a read-only peer cannot pass its
// requests off as someone else's.
#pragma once

#include <optional>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

namespace cncd::daemon {

struct Attribution {
  std::string user;
  std::string address;
  std::string via;
};

// The longest user, address and via accepted.
inline constexpr std::size_t kMaxAttributionText = 64;

// Checks the value of "on_behalf_of": an object of exactly "user", "address" and "via", each a
// string of 1 to 64 printable ASCII characters without spaces. Returns it or the error message.
std::variant<Attribution, std::string> parse_attribution(const nlohmann::json& value);

// "alice@192.168.1.20 (web) via uid 998 pid 1234": who asked, through which peer.
std::string attribution_text(const Attribution& who, const std::string& peer);

}  // namespace cncd::daemon
