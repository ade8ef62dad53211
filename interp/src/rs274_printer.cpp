#include "cncd/interp/rs274_printer.hpp"

#include <cstdio>

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

const char* plane_name(Plane plane) {
  switch (plane) {
    case Plane::yz:
      return "CANON_PLANE_YZ";
    case Plane::xz:
      return "CANON_PLANE_XZ";
    case Plane::xy:
    default:
      return "CANON_PLANE_XY";
  }
}

const char* units_name(int units) {
  switch (static_cast<Units>(units)) {
    case Units::inches:
      return "CANON_UNITS_INCHES";
    case Units::cm:
      return "CANON_UNITS_CM";
    case Units::mm:
    default:
      return "CANON_UNITS_MM";
  }
}

// The fixed-name commands: "NAME()" or "NAME(0)" for the spindle-indexed ones.
const char* simple_name(CanonKind kind) {
  switch (kind) {
    case CanonKind::start_spindle_clockwise:
      return "START_SPINDLE_CLOCKWISE(0)";
    case CanonKind::start_spindle_counterclockwise:
      return "START_SPINDLE_COUNTERCLOCKWISE(0)";
    case CanonKind::stop_spindle_turning:
      return "STOP_SPINDLE_TURNING(0)";
    case CanonKind::mist_on:
      return "MIST_ON()";
    case CanonKind::mist_off:
      return "MIST_OFF()";
    case CanonKind::flood_on:
      return "FLOOD_ON()";
    case CanonKind::flood_off:
      return "FLOOD_OFF()";
    case CanonKind::program_stop:
      return "PROGRAM_STOP()";
    case CanonKind::optional_program_stop:
      return "OPTIONAL_PROGRAM_STOP()";
    case CanonKind::program_end:
      return "PROGRAM_END()";
    case CanonKind::pallet_shuttle:
      return "PALLET_SHUTTLE()";
    case CanonKind::on_reset:
      return "ON_RESET()";
    case CanonKind::finish:
      return "FINISH()";
    case CanonKind::start_change:
      return "START_CHANGE()";
    case CanonKind::set_feed_reference:
      return "SET_FEED_REFERENCE(CANON_XYZ)";
    default:
      return nullptr;
  }
}

// Appends the command's text without its newline; `out` keeps its capacity from one command
// to the next, so printing a long program allocates nothing per command.
void append_rs274(std::string& out, const CanonCommand& c, int axes) {
  if (const char* name = simple_name(c.kind)) {
    out += name;
    return;
  }
  switch (c.kind) {
    case CanonKind::straight_traverse:
    case CanonKind::straight_feed:
      out += c.kind == CanonKind::straight_traverse ? "STRAIGHT_TRAVERSE(" : "STRAIGHT_FEED(";
      append_pose(out, c.pos, axes);
      break;
    case CanonKind::arc_feed: {
      out += "ARC_FEED(";
      append_fixed4(out, c.first_end);
      out += ", ";
      append_fixed4(out, c.second_end);
      out += ", ";
      append_fixed4(out, c.first_axis);
      out += ", ";
      append_fixed4(out, c.second_axis);
      out += ", ";
      append_int(out, c.rotation);
      out += ", ";
      append_fixed4(out, c.axis_end_point);
      for (int axis = 3; axis < axes; ++axis) {
        out += ", ";
        append_fixed4(out, c.pos[static_cast<std::size_t>(axis)]);
      }
      break;
    }
    case CanonKind::dwell:
      out += "DWELL(";
      append_fixed4(out, c.value);
      break;
    case CanonKind::set_feed_rate:
      out += "SET_FEED_RATE(";
      append_fixed4(out, c.value);
      break;
    case CanonKind::set_feed_mode:
      out += "SET_FEED_MODE(0, ";
      append_int(out, c.ivalue);
      break;
    case CanonKind::select_plane:
      out += "SELECT_PLANE(";
      out += plane_name(c.plane);
      break;
    case CanonKind::use_length_units:
      out += "USE_LENGTH_UNITS(";
      out += units_name(c.ivalue);
      break;
    case CanonKind::set_g5x_offset:
      out += "SET_G5X_OFFSET(";
      append_int(out, c.ivalue);
      out += ", ";
      append_pose(out, c.pos, axes);
      break;
    case CanonKind::set_g92_offset:
      out += "SET_G92_OFFSET(";
      append_pose(out, c.pos, axes);
      break;
    case CanonKind::set_xy_rotation:
      out += "SET_XY_ROTATION(";
      append_fixed4(out, c.value);
      break;
    case CanonKind::use_tool_length_offset:
      out += "USE_TOOL_LENGTH_OFFSET(";
      for (int axis = 0; axis < kAxes; ++axis) {
        if (axis > 0) out += axis % 3 == 0 ? ", " : " ";
        append_fixed4(out, c.pos[static_cast<std::size_t>(axis)]);
      }
      break;
    case CanonKind::set_motion_control_mode:
      switch (static_cast<MotionMode>(c.ivalue)) {
        case MotionMode::exact_stop:
          out += "SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP";
          break;
        case MotionMode::exact_path:
          out += "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH";
          break;
        case MotionMode::continuous:
        default:
          out += "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, ";
          append_printf(out, "%.6f", c.value);
          break;
      }
      break;
    case CanonKind::set_naivecam_tolerance:
      out += "SET_NAIVECAM_TOLERANCE(";
      append_fixed4(out, c.value);
      break;
    case CanonKind::set_spindle_speed:
      out += "SET_SPINDLE_SPEED(0, ";
      append_fixed4(out, c.value);
      break;
    case CanonKind::orient_spindle:
      out += "ORIENT_SPINDLE(0, ";
      append_fixed4(out, c.value);
      out += ", ";
      append_int(out, c.ivalue);
      break;
    case CanonKind::set_tool_table_entry:
      out += "SET_TOOL_TABLE_ENTRY(";
      append_int(out, c.ivalue);
      out += ", ";
      append_int(out, c.ivalue2);
      out += ", ";
      for (int axis = 0; axis < kAxes; ++axis) {
        if (axis > 0) out += ' ';
        append_fixed4(out, c.pos[static_cast<std::size_t>(axis)]);
      }
      out += ", ";
      append_fixed4(out, c.value);
      out += ", ";
      append_fixed4(out, c.value2);
      out += ", ";
      append_int(out, c.ivalue3);
      break;
    case CanonKind::set_spindle_mode:
      out += "SET_SPINDLE_MODE(0 ";
      append_fixed4(out, c.value);
      break;
    case CanonKind::select_tool:
      out += "SELECT_TOOL(";
      append_int(out, c.ivalue);
      break;
    case CanonKind::change_tool:
      out += "CHANGE_TOOL(";
      append_int(out, c.ivalue);
      break;
    case CanonKind::change_tool_number:
      out += "CHANGE_TOOL_NUMBER(";
      append_int(out, c.ivalue);
      break;
    case CanonKind::set_feed_override_enable:
      out += c.ivalue != 0 ? "ENABLE_FEED_OVERRIDE()" : "DISABLE_FEED_OVERRIDE()";
      return;
    case CanonKind::set_spindle_override_enable:
      out += c.ivalue != 0 ? "ENABLE_SPEED_OVERRIDE(0)" : "DISABLE_SPEED_OVERRIDE(0)";
      return;
    case CanonKind::set_adaptive_feed_enable:
      out += c.ivalue != 0 ? "ENABLE_ADAPTIVE_FEED()" : "DISABLE_ADAPTIVE_FEED()";
      return;
    case CanonKind::set_feed_hold_enable:
      out += c.ivalue != 0 ? "ENABLE_FEED_HOLD()" : "DISABLE_FEED_HOLD()";
      return;
    case CanonKind::comment:
      out += "COMMENT(\"";
      out += c.text;
      out += "\")";
      return;
    case CanonKind::message:
    case CanonKind::debug_message:
      out += "MESSAGE(\"";
      out += c.text;
      out += "\")";
      return;
    case CanonKind::start_spindle_clockwise:
    case CanonKind::start_spindle_counterclockwise:
    case CanonKind::stop_spindle_turning:
    case CanonKind::mist_on:
    case CanonKind::mist_off:
    case CanonKind::flood_on:
    case CanonKind::flood_off:
    case CanonKind::program_stop:
    case CanonKind::optional_program_stop:
    case CanonKind::program_end:
    case CanonKind::pallet_shuttle:
    case CanonKind::on_reset:
    case CanonKind::finish:
    case CanonKind::start_change:
    case CanonKind::set_feed_reference:
      return;  // handled above; listed so the compiler checks coverage
  }
  out += ')';
}

}  // namespace

std::string format_rs274(const CanonCommand& command, int axes) {
  std::string out;
  append_rs274(out, command, axes);
  return out;
}

void Rs274Printer::emit(const CanonCommand& command) {
  buffer_.clear();
  append_rs274(buffer_, command, axes_);
  buffer_ += '\n';
  out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
}

}  // namespace cncd::interp
