#include "cncd/config/evdev_codes.hpp"

#include <linux/input-event-codes.h>

#include <cstddef>
#include <iterator>
#include <string_view>

namespace cncd::config {
namespace {

struct Entry {
  std::string_view name;
  std::uint16_t code;
};

// Every KEY_, BTN_, REL_ and ABS_ name of the kernel's header, listed from it at build time
// (config/CMakeLists.txt), so a code a newer kernel adds is known without editing a table.
constexpr Entry kCodes[] = {
#define CNCD_EVDEV_CODE(name) {#name, name},
#include "evdev_code_names.inc"
#undef CNCD_EVDEV_CODE
};

constexpr bool starts_with(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

}  // namespace

std::uint16_t EvdevCode::event_type() const {
  static constexpr std::uint16_t kTypes[] = {EV_KEY, EV_REL, EV_ABS};  // in Type's order
  const auto index = static_cast<std::size_t>(type);
  return index < std::size(kTypes) ? kTypes[index] : EV_KEY;
}

std::optional<EvdevCode> evdev_code(std::string_view name) {
  EvdevCode out;
  if (starts_with(name, "KEY_") || starts_with(name, "BTN_")) {
    out.type = EvdevCode::Type::key;
  } else if (starts_with(name, "REL_")) {
    out.type = EvdevCode::Type::rel;
  } else if (starts_with(name, "ABS_")) {
    out.type = EvdevCode::Type::abs;
  } else {
    return std::nullopt;
  }
  for (const Entry& entry : kCodes) {
    if (entry.name == name) {
      out.code = entry.code;
      return out;
    }
  }
  return std::nullopt;
}

}  // namespace cncd::config
