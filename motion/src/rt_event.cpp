#include "cncd/motion/rt_event.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>

#include "cncd/config/enum_name.hpp"
#include "cncd/config/machine_config.hpp"

namespace cncd::motion {
namespace {

// Homing's reasons fit this many characters, a long driver name included.
constexpr std::size_t kHomingTextSize = 120;

// Clamped: printing a huge number with %f would need a large buffer.
double clamped(double value) {
  return std::min(value, 1e9);
}

int format_following_error(const RtEvent& e, char* out, std::size_t size) {
  const int n = std::snprintf(out, size, "joint %d: following error %.4f exceeds %.4f", e.joint,
                              clamped(e.error), clamped(e.limit));
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

int format_joint_fault(const RtEvent& e, const char* what, char* out, std::size_t size) {
  return std::snprintf(out, size, "joint %d: %s%s%s", e.joint, what, e.text[0] ? ": " : "", e.text);
}

char axis_letter(int axis) {
  return axis >= 0 && axis < config::kMaxAxes ? config::kAxisLetters[static_cast<std::size_t>(axis)]
                                              : '?';
}

int format(const RtEvent& e, char* out, std::size_t size) {
  using Code = RtEvent::Code;
  const char* words = e.words != nullptr ? e.words : "";
  switch (e.code) {
    case Code::none:
      return std::snprintf(out, size, "%s", "");
    case Code::estop:
      return std::snprintf(out, size, "estop");
    case Code::estop_input:
      return std::snprintf(out, size, "estop input asserted");
    case Code::home_ignored_not_on:
      return std::snprintf(out, size, "home ignored: the machine is not on");
    case Code::home_ignored_moving:
      return std::snprintf(out, size, "home ignored: the machine is moving");
    case Code::homing_aborted:
      return std::snprintf(out, size, "homing aborted");
    case Code::homing_in_progress:
      return std::snprintf(out, size, "homing is already in progress");
    case Code::homing_failed:
      return std::snprintf(out, std::min(size, kHomingTextSize), "joint %d: %s", e.joint, words);
    case Code::homing_needs_switch:
      return std::snprintf(out, std::min(size, kHomingTextSize),
                           "joint %d: switch homing needs a home switch input, which driver "
                           "'%s' lacks",
                           e.joint, e.text);
    case Code::jog_ignored:
      return std::snprintf(out, size, "jog ignored: %s", words);
    case Code::feedback_not_a_number:
      return std::snprintf(out, size, "joint %d: feedback position is not a number", e.joint);
    case Code::drive_fault:
      return format_joint_fault(e, "drive fault", out, size);
    case Code::feedback_stale:
      return format_joint_fault(e, "feedback is stale", out, size);
    case Code::min_limit_switch:
      return std::snprintf(out, size, "joint %d: minimum limit switch tripped", e.joint);
    case Code::max_limit_switch:
      return std::snprintf(out, size, "joint %d: maximum limit switch tripped", e.joint);
    case Code::following_error:
      return format_following_error(e, out, size);
    case Code::set_point_not_finite:
      return std::snprintf(out, size, "non-finite set-point on joint %d", e.joint);
    case Code::joints_apart:
      return std::snprintf(out, size,
                           "joint %d stands apart from axis %c: home the joints of an axis "
                           "together, to the same HOME",
                           e.joint, axis_letter(e.axis));
    case Code::off_path:
      return std::snprintf(out, size, "a queued move does not start where the machine stands");
    case Code::spindle_not_at_speed:
      return std::snprintf(out, size,
                           "spindle 0 did not reach %.0f rpm within %.3g s ([SPINDLE_0] "
                           "AT_SPEED_TIMEOUT): it turns at %.0f rpm",
                           clamped(e.limit), static_cast<double>(e.oldest_ago) / 1000.0,
                           clamped(e.error));
    case Code::spindle_fault:
      return std::snprintf(out, size, "spindle 0: drive fault%s%s", e.text[0] ? ": " : "", e.text);
    case Code::spindle_stale:
      return std::snprintf(out, size, "spindle 0: no answer from the drive%s%s",
                           e.text[0] ? ": " : "", e.text);
    case Code::spindle_not_oriented:
      return std::snprintf(out, size,
                           "spindle 0 did not orient to %.4g degrees within %.3g s (M19 Q): it "
                           "stands %.4g degrees off",
                           clamped(e.limit), static_cast<double>(e.oldest_ago) / 1000.0,
                           clamped(e.error));
    case Code::no_spindle:
      return std::snprintf(out, size, "the machine has no spindle ([SPINDLE_0] DRIVER = none)");
    case Code::probe_tripped_at_start:
      return std::snprintf(out, size,
                           "probe is already tripped when starting a G38.2 or G38.3 move");
    case Code::probe_untripped_at_start:
      return std::snprintf(out, size, "probe is not tripped when starting a G38.4 or G38.5 move");
    case Code::probe_no_contact:
      return std::snprintf(out, size, "G38.2 probe move finished without tripping the probe");
    case Code::probe_contact_kept:
      return std::snprintf(out, size, "G38.4 probe move finished without losing contact");
    case Code::sync_overrun:
      return std::snprintf(out, size,
                           "spindle 0 turned %.3g revolutions past the end of the rigid tap "
                           "(more than %.3g): the tap was stopped there",
                           clamped(e.error), clamped(e.limit));
    case Code::sync_stalled:
      return std::snprintf(out, size,
                           "spindle 0 did not turn for %.3g s during a move in step with it "
                           "(G33, G33.1, rigid tapping; [SPINDLE_0] AT_SPEED_TIMEOUT)",
                           clamped(e.limit));
    case Code::sync_jump:
      return std::snprintf(out, size,
                           "spindle 0's position jumped %.3g revolutions in one servo period "
                           "during a rigid tap (at most %.3g): the tap was stopped there",
                           clamped(e.error), clamped(e.limit));
    case Code::sync_not_at_rest:
      return std::snprintf(out, size,
                           "spindle 0 did not come to rest within %.3g s to start a rigid tap "
                           "([SPINDLE_0] AT_SPEED_TIMEOUT): it turns at %.4g rpm",
                           clamped(e.limit), clamped(e.error));
  }
  return std::snprintf(out, size, "servo event %d", static_cast<int>(e.code));
}

}  // namespace

std::size_t format_event(const RtEvent& event, char* out, std::size_t size) noexcept {
  if (size == 0) return 0;
  out[0] = '\0';
  const int n = format(event, out, size);
  return n < 0 ? 0 : static_cast<std::size_t>(n);
}

const char* event_code_name(RtEvent::Code code) noexcept {
  // In the enum's order.
  static constexpr const char* kNames[] = {"",
                                           "estop",
                                           "estop_input",
                                           "home_ignored_not_on",
                                           "home_ignored_moving",
                                           "homing_aborted",
                                           "homing_in_progress",
                                           "homing_failed",
                                           "homing_needs_switch",
                                           "jog_ignored",
                                           "feedback_not_a_number",
                                           "drive_fault",
                                           "feedback_stale",
                                           "min_limit_switch",
                                           "max_limit_switch",
                                           "following_error",
                                           "set_point_not_finite",
                                           "joints_apart",
                                           "off_path",
                                           "spindle_not_at_speed",
                                           "spindle_fault",
                                           "spindle_stale",
                                           "no_spindle",
                                           "spindle_not_oriented",
                                           "probe_tripped_at_start",
                                           "probe_untripped_at_start",
                                           "probe_no_contact",
                                           "probe_contact_kept",
                                           "sync_overrun",
                                           "sync_stalled",
                                           "sync_jump",
                                           "sync_not_at_rest"};
  static_assert(std::size(kNames) == static_cast<std::size_t>(RtEvent::Code::sync_not_at_rest) + 1);
  return config::enum_name(code, kNames);
}

std::string format_event(const RtEvent& event) {
  char text[kEventTextSize];
  format_event(event, text, sizeof text);
  return text;
}

}  // namespace cncd::motion
