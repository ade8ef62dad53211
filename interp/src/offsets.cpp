// Coordinate systems, G92/G52 offsets, units and tool length offsets. Offsets are kept in
// program units; the parameters hold them in machine units, as LinuxCNC's .var file does.
// Whenever an offset changes, the machine position stays put and the program position moves.
#include <cctype>
#include <cmath>
#include <numbers>

#include "cncd/interp/stored_values.hpp"
#include "cutter_comp.hpp"
#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {

bool is_linear_axis(int axis) {
  return axis <= kZ || axis >= kU;
}

void rotate_xy(Pose& pose, double degrees) {
  if (degrees == 0.0) return;
  const double angle = degrees * std::numbers::pi / 180.0;
  const double x = pose[kX] * std::cos(angle) - pose[kY] * std::sin(angle);
  const double y = pose[kX] * std::sin(angle) + pose[kY] * std::cos(angle);
  pose[kX] = x;
  pose[kY] = y;
}

double unit_factor(Units from, Units to) {
  auto mm = [](Units units) {
    return units == Units::inches ? 25.4 : units == Units::cm ? 10.0 : 1.0;
  };
  return mm(from) / mm(to);
}

Units Interpreter::Impl::tool_table_units() const {
  return options_.tool_table_units.value_or(options_.machine_units);
}

double Interpreter::Impl::to_program_units(double machine_value) const {
  return machine_value * unit_factor(options_.machine_units, modal_.units);
}

double Interpreter::Impl::to_machine_units(double program_value) const {
  return program_value * unit_factor(modal_.units, options_.machine_units);
}

Pose Interpreter::Impl::read_offset_parameters(int base) const {
  Pose offset{};
  for (int axis = 0; axis < kAxes; ++axis) {
    const double value = parameters_.get(base + axis);
    offset[static_cast<std::size_t>(axis)] = is_linear_axis(axis) ? to_program_units(value) : value;
  }
  return offset;
}

int Interpreter::Impl::word_column(char letter) const {
  return block_.has(letter) ? block_.col(letter)
                            : block_.g_column[static_cast<std::size_t>(GGroup::non_modal)];
}

void Interpreter::Impl::write_offset_parameters(int base, const Pose& offset, std::uint32_t axes) {
  Pose machine{};
  for (int axis = 0; axis < kAxes; ++axis) {
    const double value = offset[static_cast<std::size_t>(axis)];
    machine[static_cast<std::size_t>(axis)] =
        is_linear_axis(axis) ? to_machine_units(value) : value;
  }
  for (int pass = 0; pass < 2; ++pass) {
    for (int axis = 0; axis < kAxes; ++axis) {
      if (((axes >> axis) & 1U) == 0) continue;
      const double value = machine[static_cast<std::size_t>(axis)];
      const int column = word_column(kAxisLetters[axis]);
      if (pass == 0) {
        parameters_.check(base + axis, value, column);
      } else {
        parameters_.set(base + axis, value, column);
      }
    }
  }
}

void Interpreter::Impl::load_coord_system(int index) {
  const int base = kG5xBase + 20 * (index - 1);
  g5x_offset_ = read_offset_parameters(base);
  rotation_deg_ = parameters_.get(base + 9);
}

void Interpreter::Impl::emit_g5x() {
  emit(SetG5xOffset{modal_.coord_system, g5x_offset_});
}

void Interpreter::Impl::emit_g92() {
  emit(SetG92Offset{g92_offset_});
}

void Interpreter::Impl::select_coord_system_quiet(int index) {
  const Pose machine = program_to_machine(pos_);
  modal_.coord_system = index;
  parameters_.set(5220, index);
  load_coord_system(index);
  pos_ = machine_to_program(machine);
}

void Interpreter::Impl::select_coord_system(int index) {
  select_coord_system_quiet(index);
  emit_g5x();
  emit_g92();
  emit(SetXyRotation{rotation_deg_});
}

void Interpreter::Impl::change_units(Units units) {
  if (units != modal_.units) {
    const double factor = unit_factor(modal_.units, units);
    for (int axis = 0; axis < kAxes; ++axis) {
      if (!is_linear_axis(axis)) continue;
      const auto a = static_cast<std::size_t>(axis);
      pos_[a] *= factor;
      g5x_offset_[a] *= factor;
      g92_offset_[a] *= factor;
      // LinuxCNC leaves the tool length offset's number as it is (it is in the units it was
      // set in); the canon layer converted it when it was set.
    }
    Comp::comp_scale(*this, factor);
    modal_.units = units;
  }
  emit(UseLengthUnits{units});
}

// The table's length offsets of `entry` in the program's units.
Pose Interpreter::Impl::table_offset(const ToolEntry& entry) const {
  Pose offset{};
  const double factor = unit_factor(tool_table_units(), modal_.units);
  for (int axis = 0; axis < kAxes; ++axis) {
    const double value = entry.offset[static_cast<std::size_t>(axis)];
    offset[static_cast<std::size_t>(axis)] = is_linear_axis(axis) ? value * factor : value;
  }
  return offset;
}

void Interpreter::Impl::apply_tool_length(int code) {
  Pose offset{};
  if (code == 430) {
    const int tool = block_.has('h') ? to_int(block_.get('h')) : tool_in_spindle_;
    if (tool != 0) {
      const ToolEntry* entry = tools_.find(tool);
      if (entry == nullptr && !options_.tool_table.empty()) {
        fail("Requested tool " + std::to_string(tool) + " not found in the tool table",
             block_.col('h'));
      }
      if (entry != nullptr) offset = table_offset(*entry);
    }
  } else if (code == 432) {
    // G43.2 adds a table entry's offsets (a wear entry, T10000 + n as LinuxCNC's lathe
    // configurations keep them) or the line's axis words to the offsets in force.
    bool axes = false;
    for (int axis = 0; axis < kAxes; ++axis)
      axes = axes || block_.has(kAxisLetters[axis]);
    if (block_.has('h') && axes) fail("G43.2: Can not have both H and axis words");
    if (!block_.has('h') && !axes) fail("G43.2: No axes specified and H word missing");
    offset = tool_offset_;
    Pose more{};
    if (axes) {
      for (int axis = 0; axis < kAxes; ++axis) {
        const char letter = kAxisLetters[axis];
        if (block_.has(letter)) more[static_cast<std::size_t>(axis)] = block_.get(letter);
      }
    } else if (const int tool = to_int(block_.get('h')); tool != 0) {
      const ToolEntry* entry = tools_.find(tool);
      if (entry == nullptr && !options_.tool_table.empty()) {
        fail("Requested tool " + std::to_string(tool) + " not found in the tool table",
             block_.col('h'));
      }
      if (entry != nullptr) more = table_offset(*entry);
    }
    for (std::size_t axis = 0; axis < kAxes; ++axis)
      offset[axis] += more[axis];
  } else if (code == 431) {
    // G43.1 replaces the offsets of the axes it names and keeps the others.
    offset = tool_offset_;
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      if (block_.has(letter)) offset[static_cast<std::size_t>(axis)] = block_.get(letter);
    }
  }
  // The one check on the tool length offset that takes effect (G43.1 words, or a table entry
  // scaled to the program's units).
  Pose machine{};
  for (int axis = 0; axis < kAxes; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    machine[a] = is_linear_axis(axis) ? to_machine_units(offset[a]) : offset[a];
    if (!storable(machine[a])) {
      fail(out_of_range_message(std::string("Tool length offset ") +
                                    static_cast<char>(std::toupper(kAxisLetters[axis])),
                                machine[a]),
           block_.has(kAxisLetters[axis]) ? block_.col(kAxisLetters[axis]) : 0);
    }
  }
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    pos_[axis] += tool_offset_[axis] - offset[axis];
  tool_offset_ = offset;
  tool_offset_machine_ = machine;
  modal_.tool_length_code = code;
  emit(UseToolLengthOffset{tool_offset_});
}

// LinuxCNC's canon order: the G92 offset applies inside the XY rotation, the G5x origin and
// the tool offset after it.
Pose Interpreter::Impl::program_to_machine(const Pose& program) const {
  Pose p = program;
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    p[axis] += g92_offset_[axis];
  rotate_xy(p, rotation_deg_);
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    p[axis] += g5x_offset_[axis] + tool_offset_[axis];
  return p;
}

Pose Interpreter::Impl::machine_to_program(const Pose& machine) const {
  Pose p = machine;
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    p[axis] -= g5x_offset_[axis] + tool_offset_[axis];
  rotate_xy(p, -rotation_deg_);
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    p[axis] -= g92_offset_[axis];
  return p;
}

// LinuxCNC changes the G92 offset axis by axis and shifts the program position by the same
// amount on that axis (so with an XY rotation the machine point is not kept exactly).
void Interpreter::Impl::do_g92(int code) {
  const Pose old_offset = g92_offset_;
  Pose offset = g92_offset_;
  if (code == 920 || code == 520) {
    std::uint32_t axes = 0;
    for (int axis = 0; axis < kAxes; ++axis) {
      const char letter = kAxisLetters[axis];
      if (!block_.has(letter)) continue;
      axes |= 1U << axis;
      const auto a = static_cast<std::size_t>(axis);
      const double value = block_.get(letter);
      // G92: the current point gets the given coordinate; G52: the offset is the given value.
      offset[a] = code == 920 ? pos_[a] + g92_offset_[a] - value : value;
    }
    if (axes == 0) fail("All axes missing with g52 or g92", block_.g_column[0]);
    // The parameters first: an offset they refuse changes nothing.
    write_offset_parameters(kG92Base, offset, 0x1FFU);
    parameters_.set(5210, 1);
  } else if (code == 921 || code == 922) {
    offset = Pose{};
    if (code == 921) write_offset_parameters(kG92Base, offset, 0x1FFU);
    parameters_.set(5210, 0);  // G92.2 keeps the offsets' parameters but disables them
  } else {
    offset = read_offset_parameters(kG92Base);
    parameters_.set(5210, 1);
  }
  g92_offset_ = offset;
  for (std::size_t axis = 0; axis < kAxes; ++axis)
    pos_[axis] += old_offset[axis] - g92_offset_[axis];
  emit_g92();
}

void Interpreter::set_tool_in_spindle(int tool) {
  Impl& s = *impl_;
  const Pose machine = s.program_to_machine(s.pos_);
  s.tool_in_spindle_ = tool;
  if (s.modal_.tool_length_code == 430) {
    const ToolEntry* entry = tool != 0 ? s.tools_.find(tool) : nullptr;
    s.tool_offset_ = entry != nullptr ? s.table_offset(*entry) : Pose{};
    s.resend_tool_offset_ = true;
    for (int axis = 0; axis < kAxes; ++axis) {
      const auto a = static_cast<std::size_t>(axis);
      s.tool_offset_machine_[a] =
          is_linear_axis(axis) ? s.to_machine_units(s.tool_offset_[a]) : s.tool_offset_[a];
    }
  }
  s.pos_ = s.machine_to_program(machine);
}

}  // namespace cncd::interp
