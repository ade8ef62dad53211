// What the interpreter reports of itself (active codes, offsets, tools) and the changes an
// operator makes between programs (coordinate system origins, tool table entries).
#include "interp_state.hpp"

namespace cncd::interp {

namespace {
int plane_code(Plane plane) {
  if (plane == Plane::yz) return 190;
  return plane == Plane::xz ? 180 : 170;
}

int path_control_code(MotionMode mode) {
  if (mode == MotionMode::exact_stop) return 611;
  return mode == MotionMode::exact_path ? 610 : 640;
}

bool any_nonzero(const Pose& pose) {
  for (const double v : pose) {
    if (v != 0.0) return true;
  }
  return false;
}
}  // namespace

InterpState Interpreter::state() const {
  const Impl& s = *impl_;
  const ModalState& m = s.modal_;
  InterpState out;
  out.line = s.current_line_;
  auto& g = out.gcodes;
  g.fill(-1);
  g[0] = s.current_line_;
  // Numeryx: the drilling cycle in force, else the positioning mode.
  g[1] = s.nx_.cycle != 0 ? s.nx_.cycle : m.motion;
  g[2] = s.block_.g_code(GGroup::non_modal);
  g[3] = plane_code(m.plane);
  g[4] = s.comp_.side == CompSide::left ? 410 : s.comp_.side == CompSide::right ? 420 : 400;
  g[5] = m.units == Units::inches ? 200 : 210;
  g[6] = m.incremental ? 910 : 900;
  g[7] = m.feed_mode == FeedMode::inverse_time       ? 930
         : m.feed_mode == FeedMode::units_per_minute ? 940
                                                     : 950;
  g[8] = m.coord_system < 7 ? 530 + 10 * m.coord_system : 584 + m.coord_system;
  // LinuxCNC shows G43 whenever a length offset is in force, G49 otherwise.
  g[9] = m.tool_length_code != 490 || any_nonzero(s.tool_offset_) ? 430 : 490;
  g[10] = m.retract_r_plane ? 990 : 980;
  g[11] = path_control_code(m.control);
  g[13] = m.css ? 960 : 970;
  g[14] = m.arc_incremental ? 911 : 901;
  g[15] = m.diameter_mode ? 70 : 80;
  if (s.parameters_.get(5210) == 1.0) g[16] = 923;

  auto& mc = out.mcodes;
  mc.fill(-1);
  mc[0] = s.current_line_;
  mc[1] = s.block_.m_code(MGroup::stopping);
  mc[2] = m.spindle == SpindleDir::stopped ? 5 : m.spindle == SpindleDir::clockwise ? 3 : 4;
  mc[3] = s.block_.m_code(MGroup::tool_change);
  mc[4] = m.mist ? 7 : m.flood ? -1 : 9;
  mc[5] = m.flood ? 8 : -1;
  const OverrideSwitches& o = m.overrides;
  mc[6] = o.feed ? (o.speed ? 48 : 50) : (o.speed ? 51 : 49);
  mc[7] = o.adaptive_feed ? 52 : -1;
  mc[8] = o.feed_hold ? 53 : -1;

  out.coord_system = m.coord_system;
  out.rotation_deg = s.rotation_deg_;
  for (int axis = 0; axis < kAxes; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    const bool linear = is_linear_axis(axis);
    out.g5x_offset[a] = linear ? s.to_machine_units(s.g5x_offset_[a]) : s.g5x_offset_[a];
    out.g92_offset[a] = linear ? s.to_machine_units(s.g92_offset_[a]) : s.g92_offset_[a];
  }
  out.tool_offset = s.tool_offset_machine_;
  out.tool_in_spindle = s.tool_in_spindle_;
  out.tool_prepared = s.tool_prepped_;
  out.feed_rate = m.feed_rate;
  out.speed = m.speed;
  return out;
}

Pose Interpreter::coord_system_origin(int system, double* rotation_deg) const {
  const int base = kG5xBase + 20 * (system - 1);
  Pose origin{};
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    origin[axis] = impl_->parameters_.get(base + static_cast<int>(axis));
  if (rotation_deg != nullptr) *rotation_deg = impl_->parameters_.get(base + 9);
  return origin;
}

std::optional<std::string> Interpreter::set_coord_system_origin(
    int system, const Pose& origin, std::uint32_t axes, std::optional<double> rotation_deg) {
  Impl& s = *impl_;
  if (system < 1 || system > 9) return "coordinate system " + std::to_string(system) + " (1-9)";
  const int base = kG5xBase + 20 * (system - 1);
  try {
    for (int axis = 0; axis < kAxes; ++axis) {
      if (((axes >> axis) & 1U) != 0)
        s.parameters_.check(base + axis, origin[static_cast<std::size_t>(axis)]);
    }
    if (rotation_deg) s.parameters_.check(base + 9, *rotation_deg);
  } catch (const Failure& failure) {
    return failure.message;
  }
  const Pose machine = s.program_to_machine(s.pos_);
  for (int axis = 0; axis < kAxes; ++axis) {
    if (((axes >> axis) & 1U) != 0)
      s.parameters_.set(base + axis, origin[static_cast<std::size_t>(axis)]);
  }
  if (rotation_deg) s.parameters_.set(base + 9, *rotation_deg);
  if (system != s.modal_.coord_system) return std::nullopt;
  s.load_coord_system(system);
  s.pos_ = s.machine_to_program(machine);
  s.resend_g5x_ = true;
  return std::nullopt;
}

std::vector<ToolEntry> Interpreter::tools() const {
  std::vector<ToolEntry> out;
  for (const auto& [number, entry] : impl_->tools_.entries())
    out.push_back(entry);
  return out;
}

std::optional<ToolEntry> Interpreter::tool(int number) const {
  const ToolEntry* entry = impl_->tools_.find(number);
  if (entry == nullptr) return std::nullopt;
  return *entry;
}

std::optional<std::string> Interpreter::set_tool(const ToolEntry& entry) {
  return impl_->tools_.set(entry);
}

void Interpreter::set_tools(const std::vector<ToolEntry>& tools) {
  impl_->tools_.clear();
  for (const auto& entry : tools)
    impl_->tools_.set(entry);
}

std::vector<double> Interpreter::persistent_parameters() const {
  std::vector<double> out;
  for (int number = 1; number < kMaxParameter; ++number) {
    if (is_persistent_parameter(number)) out.push_back(impl_->parameters_.get(number));
  }
  return out;
}

void Interpreter::restore_persistent_parameters(const std::vector<double>& values) {
  Impl& s = *impl_;
  const Pose machine = s.program_to_machine(s.pos_);
  std::size_t next = 0;
  for (int number = 1; number < kMaxParameter && next < values.size(); ++number) {
    if (is_persistent_parameter(number)) s.parameters_.set(number, values[next++]);
  }
  const int system = to_int(s.parameters_.get(5220));
  s.modal_.coord_system = system >= 1 && system <= 9 ? system : 1;
  s.load_coord_system(s.modal_.coord_system);
  s.g92_offset_ = s.parameters_.get(5210) != 0.0 ? s.read_offset_parameters(kG92Base) : Pose{};
  s.pos_ = s.machine_to_program(machine);
  s.resend_g5x_ = true;
  s.resend_g92_ = true;
}

}  // namespace cncd::interp
