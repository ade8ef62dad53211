// What the servo thread has to say (a fault, a refused command), as a plain record: the servo
// thread fills in a code and its numbers and never formats text; format_event() puts the
// record in words on the thread that reads it (status readers, the event ring's consumer).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "cncd/drivers/fault_reason.hpp"

namespace cncd::motion {

// Room for any event's words (a driver's own words included).
inline constexpr std::size_t kEventTextSize = 240;

enum class EventLevel : std::uint8_t { info, warning, fault };

struct RtEvent {
  enum class Code : std::uint8_t {
    none,
    estop,                     // the estop command
    estop_input,               // the estop input asserted
    home_ignored_not_on,       // a home command while the machine is not on
    home_ignored_moving,       // a home command while the machine moves
    homing_aborted,            // homing stopped by an abort
    homing_in_progress,        // a home command while homing
    homing_failed,             // `joint`: `words`
    homing_needs_switch,       // `joint` homes on a switch its driver (`text`) lacks
    jog_ignored,               // `words`: why
    feedback_not_a_number,     // `joint`'s feedback position
    drive_fault,               // `joint`; `text`: the driver's words, if any
    feedback_stale,            // `joint`; `text`: the driver's words, if any
    min_limit_switch,          // `joint`'s minimum limit switch tripped
    max_limit_switch,          // `joint`'s maximum limit switch tripped
    following_error,           // `joint`: `error` over `limit`, against the commands `*_ago`
    set_point_not_finite,      // `joint`
    joints_apart,              // `joint` stands apart from its axis `axis`
    off_path,                  // a queued move starts away from the machine
    spindle_not_at_speed,      // `error` rpm actual, `limit` commanded, `oldest_ago` ms waited
    spindle_fault,             // `text`: the driver's words, if any
    spindle_stale,             // `text`: the driver's words, if any
    no_spindle,                // the program starts a spindle the machine does not have
    spindle_not_oriented,      // M19: `error` degrees off `limit` after `oldest_ago` ms
    probe_tripped_at_start,    // G38.2/G38.3 with the probe already in contact
    probe_untripped_at_start,  // G38.4/G38.5 with the probe out of contact
    probe_no_contact,          // G38.2 ended without contact
    probe_contact_kept,        // G38.4 ended without losing contact
    sync_overrun,              // the spindle went `error` rev past a tap's end (`limit` allowed)
    sync_stalled,              // the spindle did not turn in a synchronized move for `limit` s
    sync_jump,         // the spindle's position jumped `error` rev in a period (`limit` allowed)
    sync_not_at_rest,  // the spindle did not come to rest for a tap within `limit` s
  };
  Code code = Code::none;
  EventLevel level = EventLevel::info;
  std::int8_t joint = -1;
  std::int8_t axis = -1;
  // Words that live for the whole program (a string literal), or nullptr.
  const char* words = nullptr;
  double error = 0;
  double limit = 0;
  // Servo periods between the commands the feedback answered and the feedback (0: current).
  std::uint64_t oldest_ago = 0;
  std::uint64_t newest_ago = 0;
  char text[drivers::kFaultReasonSize] = {};  // a driver's own words, NUL-terminated
};

// Not RT (formats with the C library). Writes the event's words into `out` (cut to `size`,
// NUL-terminated) and returns their length before the cut.
std::size_t format_event(const RtEvent& event, char* out, std::size_t size) noexcept;
// Not RT: the words cut to kEventTextSize.
std::string format_event(const RtEvent& event);
// The code's name as the enum spells it ("following_error"), "" for none.
const char* event_code_name(RtEvent::Code code) noexcept;

}  // namespace cncd::motion
