// The modal state LinuxCNC's interpreter keeps between blocks (the G and M codes in force and
// their values), as the interpreter's blocks change it and M70-M73 save and restore it.
#pragma once

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

enum class FeedMode : int { units_per_minute = 0, inverse_time = 1, units_per_rev = 2 };
enum class SpindleDir : int { stopped = 0, clockwise = 1, counterclockwise = -1 };

// The switches of M48-M53 (modal group 9), on at start-up but adaptive feed.
struct OverrideSwitches {
  bool feed = true;   // the feed override applies
  bool speed = true;  // the spindle speed override applies
  bool adaptive_feed = false;
  bool feed_hold = true;
  bool operator==(const OverrideSwitches&) const = default;
};

// Modal state LinuxCNC keeps between blocks.
struct ModalState {
  int motion = -1;  // motion G code * 10, -1 before any motion code (LinuxCNC starts without one)
  Plane plane = Plane::xy;
  bool incremental = false;
  bool arc_incremental = true;  // G91.1 is LinuxCNC's default
  FeedMode feed_mode = FeedMode::units_per_minute;
  Units units = Units::mm;
  bool retract_r_plane = true;  // G99 is LinuxCNC's start-up retract mode
  int coord_system = 1;         // 1..9 = G54..G59.3
  MotionMode control = MotionMode::continuous;
  double tolerance = 0;        // G64 P
  double naive_tolerance = 0;  // G64 Q
  double feed_rate = 0;
  double speed = 0;
  SpindleDir spindle = SpindleDir::stopped;
  bool css = false;        // G96: S is a surface speed (units per minute), G97: rpm
  double css_max_rpm = 0;  // G96 D (absent: LinuxCNC's 1e30)
  bool mist = false;
  bool flood = false;
  OverrideSwitches overrides;
  int tool_length_code = 490;  // 430, 431 or 490
  bool diameter_mode = false;  // G7: X words are diameters; G8: radii
};

}  // namespace cncd::interp
