// The canonical machining commands the interpreter emits (NIST RS274NGC vocabulary, as
// LinuxCNC names them). Positions are in the program's current length units (the last
// USE_LENGTH_UNITS) and in program coordinates, exactly what LinuxCNC's canon layer receives;
// to_machine.hpp turns them into machine moves.
#pragma once

#include <array>
#include <cstdint>
#include <string>

namespace cncd::interp {

inline constexpr int kAxes = 9;  // X Y Z A B C U V W
using Pose = std::array<double, kAxes>;

enum class Plane : std::uint8_t { xy = 1, yz = 2, xz = 3 };  // CANON_PLANE_XY/YZ/XZ
enum class Units : std::uint8_t { inches = 1, mm = 2, cm = 3 };
enum class MotionMode : std::uint8_t { exact_stop = 1, exact_path = 2, continuous = 3 };

enum class CanonKind : std::uint8_t {
  straight_traverse,
  straight_feed,
  arc_feed,
  dwell,
  set_feed_rate,
  set_feed_mode,  // ivalue: 0 units/min, 1 inverse time; 2 units/rev
  set_feed_reference,
  select_plane,
  use_length_units,
  set_g5x_offset,           // ivalue: coordinate system 1..9; pose
  set_g92_offset,           // pose
  set_xy_rotation,          // value: degrees
  use_tool_length_offset,   // pose
  set_motion_control_mode,  // ivalue: MotionMode; value: tolerance
  set_naivecam_tolerance,
  start_spindle_clockwise,
  start_spindle_counterclockwise,
  stop_spindle_turning,
  set_spindle_speed,  // value: rpm
  set_spindle_mode,
  mist_on,
  mist_off,
  flood_on,
  flood_off,
  select_tool,               // ivalue: tool number (pocket prepared)
  change_tool,               // ivalue: tool number
  change_tool_number,        // M61
  set_feed_override_enable,  // ivalue 0/1 (M50 etc.)
  set_spindle_override_enable,
  set_adaptive_feed_enable,
  set_feed_hold_enable,
  comment,                // text
  message,                // text: (MSG,...)
  debug_message,          // text: (DEBUG,...)
  program_stop,           // M0
  optional_program_stop,  // M1
  program_end,            // M2/M30
  pallet_shuttle,         // M60 (stop)
  on_reset,
  finish,                // the program ended with a closing '%'
  start_change,          // M6: the tool change begins (emitted before CHANGE_TOOL)
  orient_spindle,        // value: angle in degrees; ivalue: LinuxCNC's orientation mode
  set_tool_table_entry,  // ivalue: pocket, ivalue2: tool, pos: offsets (tool table units),
                         // value/value2: front/back angle, ivalue3: orientation
};

struct CanonCommand {
  CanonKind kind = CanonKind::comment;
  std::int32_t line = 0;  // 1-based source line number in its file
  Pose pos{};             // end point / offset values
  // ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, a,b,c,u,v,w)
  double first_end = 0, second_end = 0, first_axis = 0, second_axis = 0, axis_end_point = 0;
  int rotation = 0;
  Plane plane = Plane::xy;  // plane of an arc
  double value = 0;         // feed rate, dwell seconds, spindle speed, tolerance, rotation angle
  double value2 = 0;        // second number (naivecam tolerance ...)
  int ivalue = 0;
  int ivalue2 = 0;  // SET_TOOL_TABLE_ENTRY: tool number
  int ivalue3 = 0;  // SET_TOOL_TABLE_ENTRY: orientation
  std::string text;
};

// Receives canonical commands in program order. Called on the interpreter's thread.
class CanonSink {
 public:
  virtual ~CanonSink() = default;
  virtual void emit(const CanonCommand& command) = 0;
};

}  // namespace cncd::interp
