#include "attribution.hpp"

#include <array>

#include "rpc_params.hpp"  // quoted_text

namespace cncd::daemon {

namespace {

// Spaces and control characters would let a name pass for more of the log line than it is
// ("alice via uid 0").
bool printable(const std::string& text) {
  for (const char c : text) {
    if (c <= ' ' || c > '~') return false;
  }
  return true;
}

// A value as the error shows it, cut short.
std::string shown(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

}  // namespace

std::variant<Attribution, std::string> parse_attribution(const nlohmann::json& value) {
  constexpr std::string_view kPrefix = "\"on_behalf_of\" ";
  constexpr std::string_view kShape =
      "an object of \"user\", \"address\" and \"via\", each a string of 1 to 64 printable "
      "characters without spaces";
  if (!value.is_object()) return std::string(kPrefix) + "must be " + std::string(kShape);
  for (const auto& [key, member] : value.items()) {
    if (key != "user" && key != "address" && key != "via") {
      return std::string(kPrefix) + "has an unknown member " + quoted_text(key) + "; it must be " +
             std::string(kShape);
    }
  }
  Attribution who;
  const std::array<std::pair<const char*, std::string*>, 3> members = {
      {{"user", &who.user}, {"address", &who.address}, {"via", &who.via}}};
  for (const auto& [name, text] : members) {
    const auto it = value.find(name);
    if (it == value.end()) return std::string(kPrefix) + "lacks \"" + name + "\"";
    if (!it->is_string() || it->get_ref<const std::string&>().empty() ||
        it->get_ref<const std::string&>().size() > kMaxAttributionText ||
        !printable(it->get_ref<const std::string&>())) {
      return std::string(kPrefix) + "member \"" + name + "\" must be a string of 1 to 64 " +
             "printable characters without spaces, not " + shown(*it);
    }
    *text = it->get<std::string>();
  }
  return who;
}

std::string attribution_text(const Attribution& who, const std::string& peer) {
  return who.user + "@" + who.address + " (" + who.via + ") via " + peer;
}

}  // namespace cncd::daemon
