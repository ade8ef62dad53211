#include "cncd/motion/rt_event.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string_view>

#include "cncd/config/machine_config.hpp"

namespace cncd::motion {
namespace {

// Homing's reasons fit this many characters, a long driver name included.
constexpr std::size_t kHomingTextSize = 120;

// What a code's format takes from the record, in its order.
enum class Fill : std::uint8_t {
  none,
  words,               // `words`
  joint,               // `joint`
  joint_words,         // `joint`, `words`; cut to kHomingTextSize
  joint_driver,        // `joint`, the driver's name in `text`; cut to kHomingTextSize
  joint_reason,        // `joint`, then ": " and `text` when there is one
  reason,              // ": " and `text` when there is one
  joint_axis,          // `joint`, the letter of `axis`
  limit_waited_error,  // `limit`, `oldest_ago` ms in s, `error`
  error_limit,         // `error`, `limit`
  limit,               // `limit`
  limit_error,         // `limit`, `error`
  following_error,     // `joint`, `error`, `limit`, then the commands it was measured against
};

// The kinds of argument each fill hands its format, in Fill's order: i int, c char, s string,
// f double.
constexpr std::string_view kArgumentKinds[] = {"",   "s",   "i",  "is", "is", "iss", "ss",
                                               "ic", "fff", "ff", "f",  "ff", "iff"};
static_assert(std::size(kArgumentKinds) == static_cast<std::size_t>(Fill::following_error) + 1);

// Whether `format`'s conversions (d f g s c, with flags and precision) take `kinds` in order.
constexpr bool takes(std::string_view format, std::string_view kinds) {
  std::size_t next = 0;
  for (std::size_t at = format.find('%'); at != std::string_view::npos; at = format.find('%', at)) {
    at = format.find_first_of("%dfgsc", at + 1);
    if (at == std::string_view::npos) return false;
    const char conversion = format[at++];
    if (conversion == '%') continue;
    const char kind = conversion == 'd' ? 'i' : conversion == 'g' ? 'f' : conversion;
    if (next == kinds.size() || kinds[next++] != kind) return false;
  }
  return next == kinds.size();
}

struct EventText {
  const char* name;  // as the enum spells the code
  const char* format;
  Fill fill = Fill::none;
};

using enum Fill;

// In the enum's order.
constexpr EventText kEvents[] = {
    {"", ""},
    {"estop", "estop"},
    {"estop_input", "estop input asserted"},
    {"home_ignored_not_on", "home ignored: the machine is not on"},
    {"home_ignored_moving", "home ignored: the machine is moving"},
    {"homing_aborted", "homing aborted"},
    {"homing_in_progress", "homing is already in progress"},
    {"homing_failed", "joint %d: %s", joint_words},
    {"homing_needs_switch",
     "joint %d: switch homing needs a home switch input, which driver '%s' lacks", joint_driver},
    {"jog_ignored", "jog ignored: %s", words},
    {"feedback_not_a_number", "joint %d: feedback position is not a number", joint},
    {"drive_fault", "joint %d: drive fault%s%s", joint_reason},
    {"feedback_stale", "joint %d: feedback is stale%s%s", joint_reason},
    {"min_limit_switch", "joint %d: minimum limit switch tripped", joint},
    {"max_limit_switch", "joint %d: maximum limit switch tripped", joint},
    {"following_error", "joint %d: following error %.4f exceeds %.4f", following_error},
    {"set_point_not_finite", "non-finite set-point on joint %d", joint},
    {"joints_apart",
     "joint %d stands apart from axis %c: home the joints of an axis together, to the same HOME",
     joint_axis},
    {"off_path", "a queued move does not start where the machine stands"},
    {"spindle_not_at_speed",
     "spindle 0 did not reach %.0f rpm within %.3g s ([SPINDLE_0] AT_SPEED_TIMEOUT): it turns at "
     "%.0f rpm",
     limit_waited_error},
    {"spindle_fault", "spindle 0: drive fault%s%s", reason},
    {"spindle_stale", "spindle 0: no answer from the drive%s%s", reason},
    {"no_spindle", "the machine has no spindle ([SPINDLE_0] DRIVER = none)"},
    {"spindle_not_oriented",
     "spindle 0 did not orient to %.4g degrees within %.3g s (M19 Q): it stands %.4g degrees off",
     limit_waited_error},
    {"probe_tripped_at_start", "probe is already tripped when starting a G38.2 or G38.3 move"},
    {"probe_untripped_at_start", "probe is not tripped when starting a G38.4 or G38.5 move"},
    {"probe_no_contact", "G38.2 probe move finished without tripping the probe"},
    {"probe_contact_kept", "G38.4 probe move finished without losing contact"},
    {"sync_overrun",
     "spindle 0 turned %.3g revolutions past the end of the rigid tap (more than %.3g): the tap "
     "was stopped there",
     error_limit},
    {"sync_stalled",
     "spindle 0 did not turn for %.3g s during a move in step with it (G33, G33.1, rigid tapping; "
     "[SPINDLE_0] AT_SPEED_TIMEOUT)",
     limit},
    {"sync_jump",
     "spindle 0's position jumped %.3g revolutions in one servo period during a rigid tap (at most "
     "%.3g): the tap was stopped there",
     error_limit},
    {"sync_not_at_rest",
     "spindle 0 did not come to rest within %.3g s to start a rigid tap ([SPINDLE_0] "
     "AT_SPEED_TIMEOUT): it turns at %.4g rpm",
     limit_error},
};
static_assert(std::size(kEvents) == static_cast<std::size_t>(RtEvent::Code::sync_not_at_rest) + 1);
static_assert(std::ranges::all_of(kEvents, [](const EventText& event) {
  return takes(event.format, kArgumentKinds[static_cast<std::size_t>(event.fill)]);
}));

// Clamped: printing a huge number with %f would need a large buffer.
double clamped(double value) {
  return std::min(value, 1e9);
}

int format_following_error(const RtEvent& e, const char* format, char* out, std::size_t size) {
  const int n = std::snprintf(out, size, format, e.joint, clamped(e.error), clamped(e.limit));
  if (n < 0 || static_cast<std::size_t>(n) >= size || e.oldest_ago == 0) return n;
  const auto oldest = static_cast<unsigned long long>(e.oldest_ago);
  const auto newest = static_cast<unsigned long long>(e.newest_ago);
  const std::size_t rest = size - static_cast<std::size_t>(n);
  const int more =
      oldest == newest
          ? std::snprintf(out + n, rest, " (against the command of %llu periods ago)", newest)
          : std::snprintf(out + n, rest, " (against the commands of %llu to %llu periods ago)",
                          oldest, newest);
  return more < 0 ? n : n + more;
}

char axis_letter(int axis) {
  return axis >= 0 && axis < config::kMaxAxes ? config::kAxisLetters[static_cast<std::size_t>(axis)]
                                              : '?';
}

int format(const RtEvent& e, char* out, std::size_t size) {
  const auto index = static_cast<std::size_t>(e.code);
  if (index >= std::size(kEvents)) {
    return std::snprintf(out, size, "servo event %d", static_cast<int>(e.code));
  }
  const char* pattern = kEvents[index].format;
  const char* said = e.words != nullptr ? e.words : "";
  const char* colon = e.text[0] ? ": " : "";
  const std::size_t homing_size = std::min(size, kHomingTextSize);
  const double waited_s = static_cast<double>(e.oldest_ago) / 1000.0;
  switch (kEvents[index].fill) {
    case none:
      return std::snprintf(out, size, "%s", pattern);
    case words:
      return std::snprintf(out, size, pattern, said);
    case joint:
      return std::snprintf(out, size, pattern, e.joint);
    case joint_words:
      return std::snprintf(out, homing_size, pattern, e.joint, said);
    case joint_driver:
      return std::snprintf(out, homing_size, pattern, e.joint, e.text);
    case joint_reason:
      return std::snprintf(out, size, pattern, e.joint, colon, e.text);
    case reason:
      return std::snprintf(out, size, pattern, colon, e.text);
    case joint_axis:
      return std::snprintf(out, size, pattern, e.joint, axis_letter(e.axis));
    case limit_waited_error:
      return std::snprintf(out, size, pattern, clamped(e.limit), waited_s, clamped(e.error));
    case error_limit:
      return std::snprintf(out, size, pattern, clamped(e.error), clamped(e.limit));
    case limit:
      return std::snprintf(out, size, pattern, clamped(e.limit));
    case limit_error:
      return std::snprintf(out, size, pattern, clamped(e.limit), clamped(e.error));
    case following_error:
      return format_following_error(e, pattern, out, size);
  }
  return 0;
}

}  // namespace

std::size_t format_event(const RtEvent& event, char* out, std::size_t size) noexcept {
  if (size == 0) return 0;
  out[0] = '\0';
  const int n = format(event, out, size);
  return n < 0 ? 0 : static_cast<std::size_t>(n);
}

const char* event_code_name(RtEvent::Code code) noexcept {
  const auto index = static_cast<std::size_t>(code);
  return index < std::size(kEvents) ? kEvents[index].name : "";
}

std::string format_event(const RtEvent& event) {
  char text[kEventTextSize];
  format_event(event, text, sizeof text);
  return text;
}

}  // namespace cncd::motion
