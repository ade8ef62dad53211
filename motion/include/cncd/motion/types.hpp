// Plain types shared by the planner, the servo thread and their clients.
#pragma once

#include <array>
#include <cstdint>

#include "cncd/config/machine_config.hpp"

namespace cncd::motion {

inline constexpr int kAxes = config::kMaxAxes;
inline constexpr int kJoints = config::kMaxJoints;

// Axis positions in machine coordinates and machine units, indexed by config::axis_index().
using AxisPose = std::array<double, kAxes>;
using JointArray = std::array<double, kJoints>;

inline constexpr int kMaxDigitalIo = config::kMaxDigitalIo;
inline constexpr int kMaxAnalogIo = config::kMaxAnalogIo;

// What the machine does at a point of the program besides moving (S and M3-M5, M7-M9,
// M64/M65, M68, M66, M6, user M codes): the servo thread does it when the path has come to
// rest there, and goes on once it is done (a wait) or at once. Trivially copyable.
struct IoAction {
  enum class Kind : std::uint8_t {
    none,
    spindle,                  // direction (-1, 0, 1) and rpm as programmed
    spindle_override_enable,  // on (M48/M49, M51)
    coolant,                  // flood, mist
    digital_output,           // index, on (M64/M65)
    analog_output,            // index, value (M68)
    wait_at_speed,            // the spindle at the commanded speed (before a feed move)
    wait_input,               // index, digital, mode, timeout_s (M66)
    hold,                     // until the task releases hold_id (M6, user M codes)
    // M19: the spindle stops and turns to `value` degrees from its zero, `mode` 0 forward (M3's
    // way), 1 in reverse, 2 the shorter way; done once it stands there, an error after
    // timeout_s. It holds there until the next spindle action.
    orient_spindle,
    wait_orient,  // M19 Q alone: until an orientation under way is done, at most timeout_s
  };
  enum class Hold : std::uint8_t { none, tool_change, user_m };
  Kind kind = Kind::none;
  std::int8_t direction = 0;
  bool on = false;
  bool flood = false;
  bool mist = false;
  bool digital = true;
  Hold hold = Hold::none;
  std::int8_t mode = 0;
  std::int16_t index = 0;
  std::uint32_t hold_id = 0;
  double rpm = 0;
  double value = 0;
  double timeout_s = 0;
  // spindle: constant surface speed (G96) when css_numerator > 0: the spindle turns at
  // css_numerator / |X - css_x_origin| rpm (X machine coordinates; css_numerator = the surface
  // speed in machine units per minute over 2 pi), at most css_max_rpm; `rpm` is then the
  // programmed surface speed.
  double css_numerator = 0;
  double css_max_rpm = 0;
  double css_x_origin = 0;
};

// Outputs set as a move starts (M62/M63, M67), exact to the servo period.
struct SyncOutputs {
  std::uint32_t set = 0;    // digital outputs turned on
  std::uint32_t clear = 0;  // digital outputs turned off
  std::uint32_t analog_mask = 0;
  std::array<double, kMaxAnalogIo> analog{};  // the values of analog_mask's outputs
  bool any() const { return (set | clear | analog_mask) != 0; }
};

// One programmed move as the task layer hands it to the planner: machine coordinates, machine
// units. Trivially copyable.
// G38.2-G38.5: a feed line that ends where the probe trips (toward) or loses contact (away);
// the "or_error" kinds make a move that ends without it an error.
enum class ProbeMode : std::uint8_t { none, toward_or_error, toward, away_or_error, away };

// Motion in step with the spindle's position: a feed line whose path position is `per_rev`
// (units of path length) per spindle revolution. thread (G33): the spindle turns as programmed
// and the path follows it from the next whole revolution. tap (G33.1, rigid G84/G74): the
// spindle is brought to rest, then driven with the axis down the line, reversed at its end and
// back to rest at its start, where its own direction and speed are restored; the path ends
// where it started.
enum class SpindleSync : std::uint8_t { none, thread, tap };

struct Move {
  // An action is a dwell of no time that does `action` (IoAction) where the path rests.
  enum class Kind : std::uint8_t { traverse, feed, arc, dwell, action };
  Kind kind = Kind::traverse;
  AxisPose end{};   // end point (traverse, feed, arc)
  double feed = 0;  // units/s along the path (feed, arc); traverse uses the limits
  // G95: units per spindle revolution; the feed then follows the spindle's actual speed
  // (`feed` is its value at the programmed speed, for planning).
  double feed_per_rev = 0;
  // Arc: centre in the plane's two axes, the plane's normal axis, turns (>0 ccw, <0 cw,
  // LinuxCNC's "rotation": 1 = one ccw arc, -1 = one cw arc, 2 = one full extra ccw turn ...).
  std::array<int, 3> plane_axes{0, 1, 2};  // first, second, normal axis index (XY: 0,1,2)
  double center_first = 0;
  double center_second = 0;
  int turns = 0;
  double dwell_s = 0;  // dwell
  // Path control in force for this move (G61.1, G61, G64), which decides how its end joins
  // the next move: exact_stop always stops there; exact_path goes on at speed only into a
  // tangent move of the same kind (feed or traverse); blend also rounds line-line corners
  // with an arc that stays within `tolerance` of the corner (G64 P; 0 = the largest arc that
  // uses at most half of each line).
  enum class PathMode : std::uint8_t { exact_stop, exact_path, blend };
  PathMode path_mode = PathMode::exact_stop;
  double tolerance = 0;  // units
  // G64 Q: consecutive feed lines of the same feed whose points all lie within this of one
  // straight line are run as that line; 0 = no merging.
  double merge_tolerance = 0;  // units
  // Tool centre point control (M428) on a table-rotary machine: `end` (and an arc's centre)
  // is the tool tip in the part's frame, and the planner cuts the move into pieces straight
  // in joint space whose tip stays within [TRAJ] TCP_TOLERANCE of the programmed path.
  bool tcp = false;
  // The Z of the tool length offset in force (G43, machine units; 0 after G49): under TCP the
  // tool's length the kinematics turns the tip with (Kinematics::tcp_inverse()).
  double tool_length = 0;
  std::int32_t line = 0;              // source line of the program, 0 = none
  IoAction action;                    // Kind::action
  SyncOutputs sync;                   // set as this move starts (traverse, feed, arc)
  ProbeMode probe = ProbeMode::none;  // a feed line that probes (exact stop at both ends)
  // A feed line in step with the spindle (exact stop at both ends): units per revolution, and
  // for a tap how much faster the spindle turns on the way out (G33.1 I, at least 1).
  SpindleSync spindle_sync = SpindleSync::none;
  double per_rev = 0;
  double retract_scale = 1;
};

}  // namespace cncd::motion
