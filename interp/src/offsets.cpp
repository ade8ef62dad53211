// Coordinate systems, G92/G52 offsets, units, tool length offsets, G10, G28/G30.
// Offsets are kept in program units; the parameters hold them in machine units, as the
// LinuxCNC .var file does for a machine of those units.
#include <cmath>
#include <numbers>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

constexpr int kG5xBase = 5221;  // G54 X; each system takes 20 parameters, R at +9
constexpr int kG92Base = 5211;
constexpr int kG28Base = 5161;
constexpr int kG30Base = 5181;

bool is_linear(int axis) {
  return axis <= kZ || axis >= kU;
}

double unit_factor(Units from, Units to) {
  auto mm = [](Units units) {
    return units == Units::inches ? 25.4 : units == Units::cm ? 10.0 : 1.0;
  };
  return mm(from) / mm(to);
}

}  // namespace

Units Interpreter::Impl::tool_table_units() const {
  return options_.tool_table_units.value_or(options_.machine_units);
}

double Interpreter::Impl::to_program_units(double machine_value) const {
  return machine_value * unit_factor(options_.machine_units, modal_.units);
}

void Interpreter::Impl::load_coord_system(int index) {
  const int base = kG5xBase + 20 * (index - 1);
  for (int axis = 0; axis < kAxes; ++axis) {
    const double value = parameters_.get(base + axis);
    g5x_offset_[static_cast<std::size_t>(axis)] = is_linear(axis) ? to_program_units(value) : value;
  }
  rotation_deg_ = parameters_.get(base + 9);
  for (int axis = 0; axis < kAxes; ++axis) {
    const double value = parameters_.get(kG92Base + axis);
    g92_offset_[static_cast<std::size_t>(axis)] = is_linear(axis) ? to_program_units(value) : value;
  }
}

void Interpreter::Impl::emit_g5x() {
  CanonCommand& command = make(CanonKind::set_g5x_offset);
  command.ivalue = modal_.coord_system;
  command.pos = g5x_offset_;
  emit(command);
}

void Interpreter::Impl::emit_g92() {
  CanonCommand& command = make(CanonKind::set_g92_offset);
  command.pos = g92_offset_;
  emit(command);
}

void Interpreter::Impl::select_coord_system_quiet(int index) {
  const Pose old_offset = g5x_offset_;
  modal_.coord_system = index;
  parameters_.set(5220, index);
  load_coord_system(index);
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    pos_[axis] += old_offset[axis] - g5x_offset_[axis];
}

void Interpreter::Impl::select_coord_system(int index) {
  select_coord_system_quiet(index);
  emit_g5x();
  emit_g92();
  emit_simple(CanonKind::set_xy_rotation, 0, rotation_deg_);
}

void Interpreter::Impl::change_units(Units units) {
  if (units != modal_.units) {
    const double factor = unit_factor(modal_.units, units);
    for (int axis = 0; axis < kAxes; ++axis) {
      if (!is_linear(axis)) continue;
      const auto a = static_cast<std::size_t>(axis);
      pos_[a] *= factor;
      g5x_offset_[a] *= factor;
      g92_offset_[a] *= factor;
      tool_offset_[a] *= factor;
    }
    modal_.units = units;
  }
  emit_simple(CanonKind::use_length_units, static_cast<int>(units));
}

void Interpreter::Impl::apply_tool_length(int code) {
  Pose offset{};
  if (code == 430) {
    const int tool = block_.has('h') ? static_cast<int>(block_.get('h')) : tool_in_spindle_;
    if (tool < 0) fail("Negative h word tool length offset index used", block_.col('h'));
    if (tool != 0) {
      const ToolEntry* entry = tools_.find(tool);
      if (entry == nullptr && !options_.tool_table.empty()) {
        fail("Requested tool " + std::to_string(tool) + " not found in the tool table",
             block_.col('h'));
      }
      if (entry != nullptr) {
        const double factor = unit_factor(tool_table_units(), modal_.units);
        for (int axis = 0; axis < kAxes; ++axis) {
          const double value = entry->offset[static_cast<std::size_t>(axis)];
          offset[static_cast<std::size_t>(axis)] = is_linear(axis) ? value * factor : value;
        }
      }
    }
  } else if (code == 431) {
    // G43.1 replaces the offsets of the axes it names and keeps the others.
    offset = tool_offset_;
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      if (block_.has(letter)) offset[static_cast<std::size_t>(axis)] = block_.get(letter);
    }
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    pos_[axis] += tool_offset_[axis] - offset[axis];
  tool_offset_ = offset;
  modal_.tool_length_code = code;
  CanonCommand& command = make(CanonKind::use_tool_length_offset);
  command.pos = tool_offset_;
  emit(command);
}

Pose Interpreter::Impl::program_to_machine(const Pose& program) const {
  Pose machine = program;
  if (rotation_deg_ != 0.0) {
    const double angle = rotation_deg_ * std::numbers::pi / 180.0;
    machine[kX] = program[kX] * std::cos(angle) - program[kY] * std::sin(angle);
    machine[kY] = program[kX] * std::sin(angle) + program[kY] * std::cos(angle);
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    machine[axis] += g5x_offset_[axis] + g92_offset_[axis] + tool_offset_[axis];
  }
  return machine;
}

Pose Interpreter::Impl::machine_to_program(const Pose& machine) const {
  Pose shifted = machine;
  for (std::size_t axis = 0; axis < kAxes; ++axis) {
    shifted[axis] -= g5x_offset_[axis] + g92_offset_[axis] + tool_offset_[axis];
  }
  if (rotation_deg_ == 0.0) return shifted;
  const double angle = -rotation_deg_ * std::numbers::pi / 180.0;
  Pose program = shifted;
  program[kX] = shifted[kX] * std::cos(angle) - shifted[kY] * std::sin(angle);
  program[kY] = shifted[kX] * std::sin(angle) + shifted[kY] * std::cos(angle);
  return program;
}

void Interpreter::Impl::do_g92(int code) {
  const Pose old_offset = g92_offset_;
  const double to_machine = unit_factor(modal_.units, options_.machine_units);
  if (code == 920 || code == 520) {
    bool any = false;
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      if (!block_.has(letter)) continue;
      any = true;
      const auto a = static_cast<std::size_t>(axis);
      const double value = block_.get(letter);
      // G92: the current point gets the given coordinate; G52: the offset is the given value.
      g92_offset_[a] = code == 920 ? pos_[a] + old_offset[a] - value : value;
    }
    if (!any) {
      fail(code == 920 ? "All axes missing with g92" : "All axes missing with g52",
           block_.g_column[0]);
    }
    parameters_.set(5210, 1);
  } else if (code == 921 || code == 922) {
    g92_offset_ = Pose{};
    if (code == 921) parameters_.set(5210, 0);
  } else {
    for (int axis = 0; axis < kAxes; ++axis) {
      const double value = parameters_.get(kG92Base + axis);
      g92_offset_[static_cast<std::size_t>(axis)] =
          is_linear(axis) ? to_program_units(value) : value;
    }
    parameters_.set(5210, 1);
  }
  if (code != 922 && code != 923) {
    for (int axis = 0; axis < kAxes; ++axis) {
      const double value = g92_offset_[static_cast<std::size_t>(axis)];
      parameters_.set(kG92Base + axis, is_linear(axis) ? value * to_machine : value);
    }
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    pos_[axis] += old_offset[axis] - g92_offset_[axis];
  emit_g92();
}

void Interpreter::Impl::do_g10() {
  if (!block_.has('l')) fail("Line number missing with g10", block_.g_column[0]);
  const int l = static_cast<int>(block_.get('l'));
  if (l != 1 && l != 2 && l != 10 && l != 11 && l != 20) {
    fail("Invalid l value with g10", block_.col('l'));
  }
  if (!block_.has('p')) fail("P word missing with g10", block_.g_column[0]);
  const int p = static_cast<int>(block_.get('p'));
  if (l == 2 || l == 20) {
    if (p < 0 || p > 9) fail("P value out of range with G10 L2", block_.col('p'));
    const int system = p == 0 ? modal_.coord_system : p;
    const int base = kG5xBase + 20 * (system - 1);
    const double to_machine = unit_factor(modal_.units, options_.machine_units);
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      if (!block_.has(letter)) continue;
      double value = block_.get(letter);
      if (l == 20) {
        // The offset that makes the current point read `value` in that system.
        const auto a = static_cast<std::size_t>(axis);
        value = pos_[a] + g5x_offset_[a] - value;
      }
      parameters_.set(base + axis, is_linear(axis) ? value * to_machine : value);
    }
    if (block_.has('r')) parameters_.set(base + 9, block_.get('r'));
    if (system == modal_.coord_system) {
      const Pose old_offset = g5x_offset_;
      load_coord_system(system);
      for (std::size_t axis = 0; axis < kAxes; ++axis) {
        pos_[axis] += old_offset[axis] - g5x_offset_[axis];
      }
      emit_g5x();
      emit_simple(CanonKind::set_xy_rotation, 0, rotation_deg_);
    }
    return;
  }
  if (p <= 0) fail("P value out of range with G10 L1", block_.col('p'));
  ToolEntry entry;
  if (const ToolEntry* existing = tools_.find(p)) entry = *existing;
  entry.number = p;
  const double to_machine = unit_factor(modal_.units, tool_table_units());
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    if (!block_.has(letter)) continue;
    const auto a = static_cast<std::size_t>(axis);
    double value = block_.get(letter);
    if (l == 10 || l == 11) {
      // The tool offset that makes the current point read `value`.
      value = pos_[a] + tool_offset_[a] - value;
    }
    entry.offset[a] = is_linear(axis) ? value * to_machine : value;
  }
  if (block_.has('r')) entry.diameter = 2.0 * block_.get('r') * to_machine;
  if (block_.has('i')) entry.front_angle = block_.get('i');
  if (block_.has('j')) entry.back_angle = block_.get('j');
  if (block_.has('q')) entry.orientation = static_cast<int>(block_.get('q'));
  tools_.set(entry);
}

void Interpreter::Impl::do_home(int code) {
  const int base = (code == 280 || code == 281) ? kG28Base : kG30Base;
  if (code == 281 || code == 301) {
    const Pose machine = program_to_machine(pos_);
    const double to_machine = unit_factor(modal_.units, options_.machine_units);
    for (int axis = 0; axis < kAxes; ++axis) {
      const double value = machine[static_cast<std::size_t>(axis)];
      parameters_.set(base + axis, is_linear(axis) ? value * to_machine : value);
    }
    return;
  }
  // Optional intermediate point (program coordinates), then the stored point (machine).
  bool any = false;
  Pose intermediate = pos_;
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    if (!block_.has(letter)) continue;
    any = true;
    const auto a = static_cast<std::size_t>(axis);
    intermediate[a] = modal_.incremental ? pos_[a] + block_.get(letter) : block_.get(letter);
  }
  if (any) straight(CanonKind::straight_traverse, intermediate);
  Pose home_machine = program_to_machine(pos_);
  for (int axis = 0; axis < kAxes; ++axis) {
    const char letter = kAxisLetters[axis];
    if (any && !block_.has(letter)) continue;
    const double value = parameters_.get(base + axis);
    home_machine[static_cast<std::size_t>(axis)] =
        is_linear(axis) ? to_program_units(value) : value;
  }
  straight(CanonKind::straight_traverse, machine_to_program(home_machine));
}

}  // namespace cncd::interp
