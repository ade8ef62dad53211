#include "cncd/interp/rs274_printer.hpp"

#include <cstdio>

namespace cncd::interp {
namespace {

void append(std::string& out, const char* format, double value) {
  char buffer[64];
  const int n = std::snprintf(buffer, sizeof buffer, format, value);
  if (n > 0) out.append(buffer, static_cast<std::size_t>(n));
}

void append_pose(std::string& out, const Pose& pose, int axes) {
  for (int axis = 0; axis < axes; ++axis) {
    if (axis > 0) out += ", ";
    append(out, "%.4f", pose[static_cast<std::size_t>(axis)]);
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

}  // namespace

std::string format_rs274(const CanonCommand& c, int axes) {
  std::string out;
  if (const char* name = simple_name(c.kind)) return name;
  switch (c.kind) {
    case CanonKind::straight_traverse:
    case CanonKind::straight_feed:
      out = c.kind == CanonKind::straight_traverse ? "STRAIGHT_TRAVERSE(" : "STRAIGHT_FEED(";
      append_pose(out, c.pos, axes);
      break;
    case CanonKind::arc_feed: {
      out = "ARC_FEED(";
      append(out, "%.4f", c.first_end);
      append(out, ", %.4f", c.second_end);
      append(out, ", %.4f", c.first_axis);
      append(out, ", %.4f", c.second_axis);
      out += ", " + std::to_string(c.rotation);
      append(out, ", %.4f", c.axis_end_point);
      for (int axis = 3; axis < axes; ++axis)
        append(out, ", %.4f", c.pos[static_cast<std::size_t>(axis)]);
      break;
    }
    case CanonKind::dwell:
      out = "DWELL(";
      append(out, "%.4f", c.value);
      break;
    case CanonKind::set_feed_rate:
      out = "SET_FEED_RATE(";
      append(out, "%.4f", c.value);
      break;
    case CanonKind::set_feed_mode:
      out = "SET_FEED_MODE(0, " + std::to_string(c.ivalue);
      break;
    case CanonKind::select_plane:
      out = std::string("SELECT_PLANE(") + plane_name(c.plane);
      break;
    case CanonKind::use_length_units:
      out = std::string("USE_LENGTH_UNITS(") + units_name(c.ivalue);
      break;
    case CanonKind::set_g5x_offset:
      out = "SET_G5X_OFFSET(" + std::to_string(c.ivalue) + ", ";
      append_pose(out, c.pos, axes);
      break;
    case CanonKind::set_g92_offset:
      out = "SET_G92_OFFSET(";
      append_pose(out, c.pos, axes);
      break;
    case CanonKind::set_xy_rotation:
      out = "SET_XY_ROTATION(";
      append(out, "%.4f", c.value);
      break;
    case CanonKind::use_tool_length_offset:
      out = "USE_TOOL_LENGTH_OFFSET(";
      for (int axis = 0; axis < kAxes; ++axis) {
        if (axis > 0) out += axis % 3 == 0 ? ", " : " ";
        append(out, "%.4f", c.pos[static_cast<std::size_t>(axis)]);
      }
      break;
    case CanonKind::set_motion_control_mode:
      switch (static_cast<MotionMode>(c.ivalue)) {
        case MotionMode::exact_stop:
          out = "SET_MOTION_CONTROL_MODE(CANON_EXACT_STOP";
          break;
        case MotionMode::exact_path:
          out = "SET_MOTION_CONTROL_MODE(CANON_EXACT_PATH";
          break;
        case MotionMode::continuous:
        default:
          out = "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, ";
          append(out, "%.6f", c.value);
          break;
      }
      break;
    case CanonKind::set_naivecam_tolerance:
      out = "SET_NAIVECAM_TOLERANCE(";
      append(out, "%.4f", c.value);
      break;
    case CanonKind::set_spindle_speed:
      out = "SET_SPINDLE_SPEED(0, ";
      append(out, "%.4f", c.value);
      break;
    case CanonKind::orient_spindle:
      out = "ORIENT_SPINDLE(0, ";
      append(out, "%.4f", c.value);
      out += ", " + std::to_string(c.ivalue);
      break;
    case CanonKind::set_tool_table_entry:
      out = "SET_TOOL_TABLE_ENTRY(" + std::to_string(c.ivalue) + ", " + std::to_string(c.ivalue2) +
            ", ";
      for (int axis = 0; axis < kAxes; ++axis) {
        if (axis > 0) out += ' ';
        append(out, "%.4f", c.pos[static_cast<std::size_t>(axis)]);
      }
      append(out, ", %.4f", c.value);
      append(out, ", %.4f", c.value2);
      out += ", " + std::to_string(c.ivalue3);
      break;
    case CanonKind::set_spindle_mode:
      out = "SET_SPINDLE_MODE(0 ";
      append(out, "%.4f", c.value);
      break;
    case CanonKind::select_tool:
      out = "SELECT_TOOL(" + std::to_string(c.ivalue);
      break;
    case CanonKind::change_tool:
      out = "CHANGE_TOOL(" + std::to_string(c.ivalue);
      break;
    case CanonKind::change_tool_number:
      out = "CHANGE_TOOL_NUMBER(" + std::to_string(c.ivalue);
      break;
    case CanonKind::set_feed_override_enable:
      return c.ivalue != 0 ? "ENABLE_FEED_OVERRIDE()" : "DISABLE_FEED_OVERRIDE()";
    case CanonKind::set_spindle_override_enable:
      return c.ivalue != 0 ? "ENABLE_SPEED_OVERRIDE(0)" : "DISABLE_SPEED_OVERRIDE(0)";
    case CanonKind::set_adaptive_feed_enable:
      return c.ivalue != 0 ? "ENABLE_ADAPTIVE_FEED()" : "DISABLE_ADAPTIVE_FEED()";
    case CanonKind::set_feed_hold_enable:
      return c.ivalue != 0 ? "ENABLE_FEED_HOLD()" : "DISABLE_FEED_HOLD()";
    case CanonKind::comment:
      return "COMMENT(\"" + c.text + "\")";
    case CanonKind::message:
    case CanonKind::debug_message:
      return "MESSAGE(\"" + c.text + "\")";
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
      return simple_name(c.kind);  // handled above; listed so the compiler checks coverage
  }
  out += ')';
  return out;
}

void Rs274Printer::emit(const CanonCommand& command) {
  buffer_ = format_rs274(command, axes_);
  buffer_ += '\n';
  out_ << buffer_;
}

}  // namespace cncd::interp
