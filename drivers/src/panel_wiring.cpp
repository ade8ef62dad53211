#include "panel_wiring.hpp"

#include <cctype>

namespace cncd::drivers {

const char* panel_counter_key(int index) {
  static constexpr const char* kKeys[] = {"MPG", "FEED_OVERRIDE", "RAPID_OVERRIDE",
                                          "SPINDLE_OVERRIDE"};
  static_assert(std::size(kKeys) == config::kPanelCounters);
  return kKeys[index];
}

std::string panel_signal_name(std::string key) {
  for (char& c : key)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return key;
}

}  // namespace cncd::drivers
