// The event codes an `evdev:` signal address names (docs/drivers.md, "USB pendants (evdev)"):
// the names of <linux/input-event-codes.h>, so that an INI says KEY_F1 or REL_DIAL as evtest
// prints them. The config checks the names and the evdev driver reads the numbers, from this
// one table.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace cncd::config {

struct EvdevCode {
  // KEY_* and BTN_* are buttons (EV_KEY), REL_* count (EV_REL), ABS_* are analog (EV_ABS).
  enum class Type : std::uint8_t { key, rel, abs };
  Type type = Type::key;
  std::uint16_t code = 0;            // the event's code (KEY_F1 = 59)
  std::uint16_t event_type() const;  // EV_KEY, EV_REL or EV_ABS
};

// The event of a code's name, upper case as the header spells it ("KEY_F1", "BTN_4",
// "REL_DIAL", "ABS_X"); nothing for a name the header does not define (and for the _MAX, _CNT
// and _RESERVED markers, which no device sends).
std::optional<EvdevCode> evdev_code(std::string_view name);

}  // namespace cncd::config
