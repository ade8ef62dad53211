// LinuxCNC's read-only parameters: the named ones (#<_x>, #<_metric> ...) computed on demand
// and the numbered ones (#5400-#5410 tool, #5420-#5428 position) refreshed after each block.
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>
#include <unordered_map>

#include "interp_state.hpp"

namespace cncd::interp {
namespace {

enum class Name : int {
  x,
  y,
  z,
  a,
  b,
  c,
  u,
  v,
  w,
  abs_x,  // the position in machine coordinates (all offsets applied), program units
  abs_y,
  abs_z,
  abs_a,
  abs_b,
  abs_c,  // LinuxCNC 2.9 has no _abs_u, _abs_v or _abs_w
  metric,
  imperial,
  absolute,
  incremental,
  inverse_time,
  units_per_minute,
  units_per_rev,
  coord_system,
  tool_offset,
  retract_r_plane,
  retract_old_z,
  spindle_rpm_mode,
  spindle_css_mode,
  ijk_absolute_mode,
  lathe_diameter_mode,
  lathe_radius_mode,
  spindle_on,
  spindle_cw,
  mist,
  flood,
  speed_override,
  feed_override,
  adaptive_feed,
  feed_hold,
  feed,
  rpm,
  ccomp,
  current_tool,
  current_pocket,
  selected_tool,
  selected_pocket,
  value,
  value_returned,
  call_level,
  remap_level,
  line,
  motion_mode,
  plane,
  task,
  vmajor,
  vminor,
};

const std::unordered_map<std::string_view, Name>& names() {
  static const std::unordered_map<std::string_view, Name> table{
      {"_x", Name::x},
      {"_y", Name::y},
      {"_z", Name::z},
      {"_a", Name::a},
      {"_b", Name::b},
      {"_c", Name::c},
      {"_u", Name::u},
      {"_v", Name::v},
      {"_w", Name::w},
      {"_abs_x", Name::abs_x},
      {"_abs_y", Name::abs_y},
      {"_abs_z", Name::abs_z},
      {"_abs_a", Name::abs_a},
      {"_abs_b", Name::abs_b},
      {"_abs_c", Name::abs_c},
      {"_metric", Name::metric},
      {"_imperial", Name::imperial},
      {"_absolute", Name::absolute},
      {"_incremental", Name::incremental},
      {"_inverse_time", Name::inverse_time},
      {"_units_per_minute", Name::units_per_minute},
      {"_units_per_rev", Name::units_per_rev},
      {"_coord_system", Name::coord_system},
      {"_tool_offset", Name::tool_offset},
      {"_retract_r_plane", Name::retract_r_plane},
      {"_retract_old_z", Name::retract_old_z},
      {"_spindle_rpm_mode", Name::spindle_rpm_mode},
      {"_spindle_css_mode", Name::spindle_css_mode},
      {"_ijk_absolute_mode", Name::ijk_absolute_mode},
      {"_lathe_diameter_mode", Name::lathe_diameter_mode},
      {"_lathe_radius_mode", Name::lathe_radius_mode},
      {"_spindle_on", Name::spindle_on},
      {"_spindle_cw", Name::spindle_cw},
      {"_mist", Name::mist},
      {"_flood", Name::flood},
      {"_speed_override", Name::speed_override},
      {"_feed_override", Name::feed_override},
      {"_adaptive_feed", Name::adaptive_feed},
      {"_feed_hold", Name::feed_hold},
      {"_feed", Name::feed},
      {"_rpm", Name::rpm},
      {"_ccomp", Name::ccomp},
      {"_current_tool", Name::current_tool},
      {"_current_pocket", Name::current_pocket},
      {"_selected_tool", Name::selected_tool},
      {"_selected_pocket", Name::selected_pocket},
      {"_value", Name::value},
      {"_value_returned", Name::value_returned},
      {"_call_level", Name::call_level},
      {"_remap_level", Name::remap_level},
      {"_line", Name::line},
      {"_motion_mode", Name::motion_mode},
      {"_plane", Name::plane},
      {"_task", Name::task},
      {"_vmajor", Name::vmajor},
      {"_vminor", Name::vminor},
  };
  return table;
}

double flag(bool value) {
  return value ? 1.0 : 0.0;
}

}  // namespace

std::optional<double> Interpreter::Impl::predefined_parameter(std::string_view name) const {
  if (name.starts_with("_ini[")) return ini_parameter(name);
  const auto it = names().find(name);
  if (it == names().end()) return std::nullopt;
  const Name n = it->second;
  if (n <= Name::w) return pos_[static_cast<std::size_t>(n)];
  if (n <= Name::abs_c) {
    return program_to_machine(
        pos_)[static_cast<std::size_t>(static_cast<int>(n) - static_cast<int>(Name::abs_x))];
  }
  static constexpr int kSystems[] = {540, 550, 560, 570, 580, 590, 591, 592, 593};
  const ToolEntry* selected = tools_.find(tool_prepped_);
  const ToolEntry* current = tools_.find(tool_in_spindle_);
  switch (n) {
    case Name::metric:
      return flag(modal_.units == Units::mm);
    case Name::imperial:
      return flag(modal_.units == Units::inches);
    case Name::absolute:
      return flag(!modal_.incremental);
    case Name::incremental:
      return flag(modal_.incremental);
    case Name::inverse_time:
      return flag(modal_.feed_mode == FeedMode::inverse_time);
    case Name::units_per_minute:
      return flag(modal_.feed_mode == FeedMode::units_per_minute);
    case Name::units_per_rev:
      return flag(modal_.feed_mode == FeedMode::units_per_rev);
    case Name::coord_system:
      return kSystems[modal_.coord_system - 1];
    case Name::tool_offset:
      return flag(modal_.tool_length_code != 490);
    case Name::retract_r_plane:
      return flag(modal_.retract_r_plane);
    case Name::retract_old_z:
      return flag(!modal_.retract_r_plane);
    case Name::spindle_rpm_mode:
      return flag(!modal_.css);
    case Name::spindle_css_mode:
      return flag(modal_.css);
    case Name::ijk_absolute_mode:
      return flag(!modal_.arc_incremental);
    case Name::lathe_diameter_mode:
      return flag(modal_.diameter_mode);
    case Name::lathe_radius_mode:
      return flag(!modal_.diameter_mode);
    case Name::spindle_on:
      return flag(modal_.spindle != SpindleDir::stopped);
    case Name::spindle_cw:
      return flag(modal_.spindle == SpindleDir::clockwise);
    case Name::ccomp:
      return comp_.side == CompSide::left ? 410.0 : comp_.side == CompSide::right ? 420.0 : 400.0;
    case Name::mist:
      return flag(modal_.mist);
    case Name::flood:
      return flag(modal_.flood);
    case Name::speed_override:
      return flag(modal_.overrides.speed);
    case Name::feed_override:
      return flag(modal_.overrides.feed);
    case Name::adaptive_feed:
      return flag(modal_.overrides.adaptive_feed);
    case Name::feed_hold:
      return flag(modal_.overrides.feed_hold);
    case Name::feed:
      return modal_.feed_rate;
    case Name::rpm:
      return modal_.speed;
    case Name::current_tool:
      return tool_in_spindle_;
    case Name::current_pocket:
      return current != nullptr ? current->pocket : 0;
    case Name::selected_tool:
      return tool_prepped_;
    case Name::selected_pocket:
      return selected != nullptr ? selected->pocket : -1;
    case Name::value:
      return last_value_;
    case Name::value_returned:
      return flag(value_returned_);
    case Name::call_level:
      return static_cast<double>(calls_.size());
    case Name::line:
      return current_line_;
    case Name::motion_mode:
      return modal_.motion < 0 ? 800 : modal_.motion;
    case Name::plane:
      switch (modal_.plane) {
        case Plane::xz:
          return 180;
        case Plane::yz:
          return 190;
        case Plane::uv:
          return 171;
        case Plane::uw:
          return 181;
        case Plane::vw:
          return 191;
        case Plane::xy:
          break;
      }
      return 170;
    case Name::vmajor:
      return 2.9;
    default:
      return 0.0;
  }
}

// #<_ini[SECTION]KEY>, as LinuxCNC reads it: the name upper-cased, then the INI's own names
// matched exactly; a value that is not wholly a number is no value.
std::optional<double> Interpreter::Impl::ini_parameter(std::string_view name) const {
  const auto close = name.find(']');
  if (!options_.ini_value || close == std::string_view::npos || close + 1 >= name.size())
    return std::nullopt;
  std::string section(name.substr(5, close - 5));
  std::string key(name.substr(close + 1));
  for (auto* text : {&section, &key}) {
    for (char& c : *text)
      c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  const auto text = options_.ini_value(section, key);
  if (!text) return std::nullopt;
  const char* begin = text->c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin) return std::nullopt;
  while (*end == ' ' || *end == '\t')
    ++end;
  if (*end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

void Interpreter::Impl::publish_parameters() {
  for (int axis = 0; axis < kAxes; ++axis) {
    parameters_.set(5420 + axis, pos_[static_cast<std::size_t>(axis)]);
  }
  parameters_.set(5400, tool_in_spindle_);
  const ToolEntry* tool = tools_.find(tool_in_spindle_);
  for (int axis = 0; axis < kAxes; ++axis) {
    parameters_.set(5401 + axis,
                    tool != nullptr ? tool->offset[static_cast<std::size_t>(axis)] : 0.0);
  }
  parameters_.set(5410, tool != nullptr ? tool->diameter : 0.0);
}

}  // namespace cncd::interp
