// G10 (coordinate system and tool table data) and G28/G30 (stored positions).
#include <cmath>
#include <numbers>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

constexpr int kG28Base = 5161;
constexpr int kG30Base = 5181;

}  // namespace

void Interpreter::Impl::do_g10() {
  const int l = block_.has('l') ? to_int(block_.get('l')) : -1;
  if (l != 1 && l != 2 && l != 10 && l != 11 && l != 20) {
    fail("Line with G10 does not have L0, L1, L10, L11, L2, or L20", block_.g_column[0]);
  }
  const int p = block_.has('p') ? to_int(std::nearbyint(block_.get('p'))) : -1;
  if (l == 2 || l == 20) {
    if (p < 0 || p > 9) fail("P value out of range (0-9) with G10 L" + std::to_string(l));
    if (block_.has('i') || block_.has('j')) fail("I J words not allowed with G10 L2");
    if (l == 20 && block_.has('r')) fail("R not allowed in G10 L20");
    set_coord_system_data(l, p == 0 ? modal_.coord_system : p);
    return;
  }
  if (p < 1) fail("P value out of range with G10 L1");
  set_tool_data(l, p);
}

void Interpreter::Impl::set_coord_system_data(int l, int system) {
  const int base = kG5xBase + 20 * (system - 1);
  Pose origin = read_offset_parameters(base);
  double rotation = parameters_.get(base + 9);
  std::uint32_t axes = 0;
  if (l == 20) {
    // The origin that makes the current point read the given coordinates in that system
    // (with its rotation; the G92 offset stays as it is).
    Pose wanted = pos_;
    for (int axis = 0; axis < kAxes; ++axis) {
      if (block_.has(kAxisLetters[axis])) {
        wanted[static_cast<std::size_t>(axis)] = block_.get(kAxisLetters[axis]);
      }
    }
    Pose now = pos_;
    rotate_xy(now, rotation_deg_);
    rotate_xy(wanted, rotation);
    for (int axis = 0; axis < kAxes; ++axis) {
      const auto a = static_cast<std::size_t>(axis);
      const bool named = block_.has(kAxisLetters[axis]);
      const bool turned =
          (axis == kX || axis == kY) && rotation != 0.0 && (block_.has('x') || block_.has('y'));
      if (!named && !turned) continue;
      axes |= 1U << axis;
      origin[a] = now[a] + g5x_offset_[a] - wanted[a];
    }
  } else {
    for (int axis = 0; axis < kAxes; ++axis) {
      if (!block_.has(kAxisLetters[axis])) continue;
      axes |= 1U << axis;
      origin[static_cast<std::size_t>(axis)] = block_.get(kAxisLetters[axis]);
    }
    if (block_.has('r')) rotation = block_.get('r');
  }
  parameters_.check(base + 9, rotation, word_column('r'));
  write_offset_parameters(base, origin, axes);
  parameters_.set(base + 9, rotation, word_column('r'));
  if (system != modal_.coord_system) {
    emit_comment("interpreter: setting coordinate system origin");
    return;
  }
  // LinuxCNC keeps the rotated program point plus the origin where it was; the G92 offset
  // takes no part in this (unlike a change of coordinate system).
  Pose fixed = pos_;
  rotate_xy(fixed, rotation_deg_);
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    fixed[axis] += g5x_offset_[axis];
  load_coord_system(system);
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    fixed[axis] -= g5x_offset_[axis];
  rotate_xy(fixed, -rotation_deg_);
  pos_ = fixed;
  emit_g5x();
  emit(SetXyRotation{rotation_deg_});
}

void Interpreter::Impl::set_tool_data(int l, int tool) {
  const ToolEntry* existing = tools_.find(tool);
  if (existing == nullptr && !options_.tool_table.empty()) {
    fail("Requested tool " + std::to_string(tool) + " not found in the tool table");
  }
  ToolEntry entry = existing != nullptr ? *existing : ToolEntry{};
  entry.number = tool;
  if (existing == nullptr) entry.pocket = tool;
  const double to_table = unit_factor(modal_.units, tool_table_units());
  const Pose g59_3 = read_offset_parameters(kG5xBase + 20 * 8);
  const Pose machine = program_to_machine(pos_);
  // L10: the offset that makes the current point read the given coordinates with this tool.
  // The offset is in machine axes: under a rotated system the program's X and Y shift both.
  Pose shift = pos_;
  for (int axis = 0; axis < kAxes; ++axis) {
    if (block_.has(kAxisLetters[axis]))
      shift[static_cast<std::size_t>(axis)] -= block_.get(kAxisLetters[axis]);
    else
      shift[static_cast<std::size_t>(axis)] = 0;
  }
  rotate_xy(shift, rotation_deg_);
  const bool turned = l == 10 && rotation_deg_ != 0.0 && (block_.has('x') || block_.has('y'));
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    const bool xy = axis == kX || axis == kY;
    if (!block_.has(letter) && !(turned && xy)) continue;
    const auto a = static_cast<std::size_t>(axis);
    double value = block_.has(letter) ? block_.get(letter) : 0.0;
    if (l == 10) {
      value = tool_offset_[a] + shift[a];
    } else if (l == 11) {
      // The same, measured in the G59.3 system.
      value = machine[a] - g59_3[a] - value;
    }
    entry.offset[a] = is_linear_axis(axis) ? value * to_table : value;
  }
  if (block_.has('r')) entry.diameter = 2.0 * block_.get('r') * to_table;
  if (block_.has('i')) entry.front_angle = block_.get('i');
  if (block_.has('j')) entry.back_angle = block_.get('j');
  if (block_.has('q')) entry.orientation = to_int(block_.get('q'));
  if (auto problem = tools_.set(entry)) fail(*problem, block_.g_column[0]);
  auto report = [&](int pocket) {
    emit(SetToolTableEntry{pocket, entry.number, entry.offset, entry.front_angle, entry.back_angle,
                           entry.orientation});
  };
  report(tools_.slot(tool));
  if (tool == tool_in_spindle_) report(0);  // the spindle is pocket 0
}

void Interpreter::Impl::do_home(int code) {
  const int base = (code == 280 || code == 281) ? kG28Base : kG30Base;
  if (code == 281 || code == 301) {
    write_offset_parameters(base, program_to_machine(pos_), 0x1FFU);
    return;
  }
  // An intermediate point (program coordinates, the current one when no axis is named), then
  // the stored point (machine coordinates) for the named axes, or all of them.
  bool any = false;
  Pose intermediate = pos_;
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    if (!block_.has(letter)) continue;
    any = true;
    const auto a = static_cast<std::size_t>(axis);
    intermediate[a] = modal_.incremental ? pos_[a] + block_.get(letter) : block_.get(letter);
  }
  straight(StraightKind::traverse, intermediate);
  // The stored point is in machine coordinates: the whole point is taken to program
  // coordinates, then only the named axes (or all) move there.
  const Pose home = machine_to_program(read_offset_parameters(base));
  Pose end = pos_;
  for (int axis = 0; axis < kAxes; ++axis) {
    if (any && !block_.has(kAxisLetters[axis])) continue;
    end[static_cast<std::size_t>(axis)] = home[static_cast<std::size_t>(axis)];
  }
  straight(StraightKind::traverse, end);
}

}  // namespace cncd::interp
