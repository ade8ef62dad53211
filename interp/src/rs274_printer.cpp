#include "cncd/interp/rs274_printer.hpp"

#include <cstdio>
#include <iterator>
#include <variant>

#include "cncd/interp/fixed_text.hpp"

namespace cncd::interp {
namespace {

void append_printf(std::string& out, const char* format, double value) {
  char buffer[400];
  const int n = std::snprintf(buffer, sizeof buffer, format, value);
  if (n > 0) out.append(buffer, static_cast<std::size_t>(n));
}

void append_pose(std::string& out, const Pose& pose, int axes) {
  for (int axis = 0; axis < axes; ++axis) {
    if (axis > 0) out += ", ";
    append_fixed4(out, pose[static_cast<std::size_t>(axis)]);
  }
}

// As rs274 names them; it has no names for the UVW planes.
const char* plane_name(Plane plane) {
  constexpr const char* kNames[] = {"CANON_PLANE_XY",      "CANON_PLANE_YZ",
                                    "CANON_PLANE_XZ",      "CANON_PLANE_UNKNOWN",
                                    "CANON_PLANE_UNKNOWN", "CANON_PLANE_UNKNOWN"};
  const std::size_t index = static_cast<std::size_t>(plane) - 1;  // from Plane::xy = 1
  return index < std::size(kNames) ? kNames[index] : kNames[0];
}

const char* units_name(Units units) {
  constexpr const char* kNames[] = {"CANON_UNITS_INCHES", "CANON_UNITS_MM", "CANON_UNITS_CM"};
  const std::size_t index = static_cast<std::size_t>(units) - 1;  // from Units::inches = 1
  return index < std::size(kNames) ? kNames[index] : "CANON_UNITS_MM";
}

// Offsets in the tool table's layout: X Y Z, A B C and U V W in groups of three.
void append_offset_groups(std::string& out, const Pose& pose, const char* group_separator) {
  for (int axis = 0; axis < kAxes; ++axis) {
    if (axis > 0) out += axis % 3 == 0 ? group_separator : " ";
    append_fixed4(out, pose[static_cast<std::size_t>(axis)]);
  }
}

// A number as rs274 prints it: %.4f, or an integer.
void append_value(std::string& out, double value) {
  append_fixed4(out, value);
}

void append_value(std::string& out, int value) {
  append_int(out, value);
}

// Arguments separated by ", ".
template <class... Values>
void append_args(std::string& out, Values... values) {
  bool first = true;
  ((out += first ? "" : ", ", first = false, append_value(out, values)), ...);
}

void append_arc(std::string& out, const ArcFeed& c, int axes) {
  out += "ARC_FEED(";
  append_args(out, c.first_end, c.second_end, c.first_axis, c.second_axis, c.rotation,
              c.axis_end_point);
  for (int axis = 3; axis < axes; ++axis) {
    out += ", ";
    append_fixed4(out, c.abc_uvw[static_cast<std::size_t>(axis - 3)]);
  }
  out += ')';
}

void append_motion_control_mode(std::string& out, const SetMotionControlMode& c) {
  switch (c.mode) {
    case MotionMode::exact_stop:
      out += "SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP)";
      break;
    case MotionMode::exact_path:
      out += "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH)";
      break;
    case MotionMode::continuous:
    default:
      out += "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, ";
      append_printf(out, "%.6f", c.tolerance);
      out += ')';
      break;
  }
}

void append_tool_table_entry(std::string& out, const SetToolTableEntry& c) {
  out += "SET_TOOL_TABLE_ENTRY(";
  append_args(out, c.pocket, c.tool);
  out += ", ";
  append_offset_groups(out, c.offset, " ");
  out += ", ";
  append_args(out, c.front_angle, c.back_angle, c.orientation);
  out += ')';
}

template <class Value>
void append_call(std::string& out, const char* name_and_paren, Value value) {
  out += name_and_paren;
  append_value(out, value);
  out += ')';
}

void append_text_call(std::string& out, const char* name, const std::string& text) {
  out += name;
  out += "(\"";
  out += text;
  out += "\")";
}

void append_pose_call(std::string& out, const char* name_and_paren, const Pose& pose, int axes) {
  out += name_and_paren;
  append_pose(out, pose, axes);
  out += ')';
}

// Appends the command's text without its newline; `out` keeps its capacity from one command
// to the next, so printing a long program allocates nothing per command.
void append_rs274(std::string& out, const CanonOp& op, int axes) {
  std::visit(
      Overloaded{
          [&](const StraightTraverse& c) {
            append_pose_call(out, "STRAIGHT_TRAVERSE(", c.end, axes);
          },
          [&](const StraightFeed& c) { append_pose_call(out, "STRAIGHT_FEED(", c.end, axes); },
          [&](const ArcFeed& c) { append_arc(out, c, axes); },
          [&](const NurbsFeed& c) {
            out += "NURBS_FEED(";
            append_int(out, static_cast<int>(c.points.size()));
            out += ", ...)";
          },
          [&](const Dwell& c) { append_call(out, "DWELL(", c.seconds); },
          [&](const SetFeedRate& c) { append_call(out, "SET_FEED_RATE(", c.rate); },
          [&](const SetFeedMode& c) {
            append_call(out, "SET_FEED_MODE(0, ", static_cast<int>(c.mode));
          },
          [&](const SetFeedReference&) { out += "SET_FEED_REFERENCE(CANON_XYZ)"; },
          [&](const SelectPlane& c) {
            out += "SELECT_PLANE(";
            out += plane_name(c.plane);
            out += ')';
          },
          [&](const UseLengthUnits& c) {
            out += "USE_LENGTH_UNITS(";
            out += units_name(c.units);
            out += ')';
          },
          [&](const SetG5xOffset& c) {
            out += "SET_G5X_OFFSET(";
            append_value(out, c.system);
            out += ", ";
            append_pose(out, c.offset, axes);
            out += ')';
          },
          [&](const SetG92Offset& c) { append_pose_call(out, "SET_G92_OFFSET(", c.offset, axes); },
          [&](const SetXyRotation& c) { append_call(out, "SET_XY_ROTATION(", c.degrees); },
          [&](const UseToolLengthOffset& c) {
            out += "USE_TOOL_LENGTH_OFFSET(";
            append_offset_groups(out, c.offset, ", ");
            out += ')';
          },
          [&](const SetMotionControlMode& c) { append_motion_control_mode(out, c); },
          [&](const SetNaivecamTolerance& c) {
            append_call(out, "SET_NAIVECAM_TOLERANCE(", c.tolerance);
          },
          [&](const StartSpindleClockwise&) { out += "START_SPINDLE_CLOCKWISE(0)"; },
          [&](const StartSpindleCounterclockwise&) { out += "START_SPINDLE_COUNTERCLOCKWISE(0)"; },
          [&](const StopSpindleTurning&) { out += "STOP_SPINDLE_TURNING(0)"; },
          [&](const SetSpindleSpeed& c) { append_call(out, "SET_SPINDLE_SPEED(0, ", c.rpm); },
          [&](const SetSpindleMode& c) { append_call(out, "SET_SPINDLE_MODE(0 ", c.css_max_rpm); },
          [&](const MistOn&) { out += "MIST_ON()"; },
          [&](const MistOff&) { out += "MIST_OFF()"; },
          [&](const FloodOn&) { out += "FLOOD_ON()"; },
          [&](const FloodOff&) { out += "FLOOD_OFF()"; },
          [&](const SelectTool& c) { append_call(out, "SELECT_TOOL(", c.tool); },
          [&](const ChangeTool& c) { append_call(out, "CHANGE_TOOL(", c.slot); },
          [&](const ChangeToolNumber& c) { append_call(out, "CHANGE_TOOL_NUMBER(", c.slot); },
          [&](const SetTcp& c) { out += c.on ? "TCP_ON()" : "TCP_OFF()"; },
          [&](const SetFeedOverrideEnable& c) {
            out += c.on ? "ENABLE_FEED_OVERRIDE()" : "DISABLE_FEED_OVERRIDE()";
          },
          [&](const SetSpindleOverrideEnable& c) {
            out += c.on ? "ENABLE_SPEED_OVERRIDE(0)" : "DISABLE_SPEED_OVERRIDE(0)";
          },
          [&](const SetAdaptiveFeedEnable& c) {
            out += c.on ? "ENABLE_ADAPTIVE_FEED()" : "DISABLE_ADAPTIVE_FEED()";
          },
          [&](const SetFeedHoldEnable& c) {
            out += c.on ? "ENABLE_FEED_HOLD()" : "DISABLE_FEED_HOLD()";
          },
          [&](const Comment& c) { append_text_call(out, "COMMENT", c.text); },
          [&](const Message& c) { append_text_call(out, "MESSAGE", c.text); },
          [&](const DebugMessage& c) { append_text_call(out, "MESSAGE", c.text); },
          [&](const ProgramStop&) { out += "PROGRAM_STOP()"; },
          [&](const OptionalProgramStop&) { out += "OPTIONAL_PROGRAM_STOP()"; },
          [&](const ProgramEnd&) { out += "PROGRAM_END()"; },
          [&](const PalletShuttle&) { out += "PALLET_SHUTTLE()"; },
          [&](const OnReset&) { out += "ON_RESET()"; },
          [&](const Finish&) { out += "FINISH()"; },
          [&](const StartChange&) { out += "START_CHANGE()"; },
          [&](const OrientSpindle& c) {
            out += "ORIENT_SPINDLE(0, ";
            append_args(out, c.angle_deg, c.mode);
            out += ')';
          },
          [&](const WaitOrientSpindle& c) {
            out += "SPINDLE.0.WAIT_ORIENT_COMPLETE(";
            append_fixed4(out, c.timeout_s);
            out += ')';
          },
          [&](const SetToolTableEntry& c) { append_tool_table_entry(out, c); },
          [&](const SetOutputBit& c) {
            out += c.on ? "SET_" : "CLEAR_";
            out += c.motion ? "MOTION_OUTPUT_BIT(" : "AUX_OUTPUT_BIT(";
            out += std::to_string(c.index);
            out += ')';
          },
          [&](const SetOutputValue& c) {
            out += c.motion ? "SET_MOTION_OUTPUT_VALUE(" : "SET_AUX_OUTPUT_VALUE(";
            out += std::to_string(c.index);
            out += ',';
            out += std::to_string(c.value);
            out += ')';
          },
          // rs274's WAIT prints nothing (only the machine's canon acts on it): no line.
          [&](const WaitInput&) {},
          [&](const UserMCode& c) {
            out += "USER_M_CODE(";
            append_args(out, c.code, c.p, c.q);
            out += ')';
          },
          [&](const TurnProbeOn&) { out += "TURN_PROBE_ON()"; },
          [&](const TurnProbeOff&) { out += "TURN_PROBE_OFF()"; },
          [&](const StraightProbe& c) { append_pose_call(out, "STRAIGHT_PROBE(", c.end, axes); },
          [&](const StartSpeedFeedSynch& c) {
            char text[64];
            std::snprintf(text, sizeof text, "START_SPEED_FEED_SYNC(%f,%d)", c.feed_per_rev,
                          c.velocity_mode ? 1 : 0);
            out += text;
          },
          [&](const StopSpeedFeedSynch&) { out += "STOP_SPEED_FEED_SYNCH()"; },
          [&](const RigidTap& c) { append_pose_call(out, "RIGID_TAP(", c.end, 3); },
      },
      op);
}

}  // namespace

std::string format_rs274(const CanonCommand& command, int axes) {
  std::string out;
  append_rs274(out, command.op, axes);
  return out;
}

void Rs274Printer::emit(const CanonCommand& command) {
  buffer_.clear();
  append_rs274(buffer_, command.op, axes_);
  if (buffer_.empty()) return;  // a command rs274 does not print
  buffer_ += '\n';
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
}

}  // namespace cncd::interp
