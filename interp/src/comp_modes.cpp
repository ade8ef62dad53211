// G40, G41, G42, G41.1 and G42.1: turning cutter radius compensation on and off, with
// LinuxCNC's checks, and the radius from the tool table (G41/G42) or the block (G41.1/G42.1).
#include <cmath>
#include <string>

#include "cutter_comp.hpp"
#include "failure.hpp"

namespace cncd::interp {

// A tool table length in program units. A table in inches is converted as LinuxCNC converts
// it, through millimetres with its 0.03937007874016 inches per millimetre (so a 1 in tool is
// a hair under 1 in in an inch program, which decides whether it fits an arc of its radius).
static double table_length(double value, Units table, Units program) {
  if (table != Units::inches) return value * unit_factor(table, program);
  const double mm = value / 0.03937007874016;
  return program == Units::inches ? mm / 25.4 : program == Units::cm ? mm / 10.0 : mm;
}

void Interpreter::Impl::Comp::comp_off(Impl& s) {
  CompState& c = s.comp_;
  s.emit_comment("interpreter: cutter radius compensation off");
  if (c.on() && c.radius > 0.0 && !c.first_move) {
    const CompAxes axes = comp_axes(s.modal_.plane);
    comp_move_end_and_flush(s, {s.pos_[axes.a], s.pos_[axes.b]});
    comp_dequeue(s);
    // The interpreter's position is the programmed one again; the next move starts from the
    // tool's compensated end all the same.
    s.pos_[axes.a] = c.program[axes.a];
    s.pos_[axes.b] = c.program[axes.b];
    s.pos_[axes.c] = c.program[axes.c];
    c.arc_not_allowed = true;
  }
  c.side = CompSide::off;
  c.first_move = true;
  s.parameters_.hide_position(false);
}

void Interpreter::Impl::Comp::comp_on(Impl& s, int code) {
  CompState& c = s.comp_;
  const Block& block = s.block_;
  const int column = block.g_column[static_cast<std::size_t>(GGroup::cutter_comp)];
  if (s.modal_.plane != Plane::xy && s.modal_.plane != Plane::xz) {
    fail("Cutter radius compensation allowed only in XY, XZ planes", column);
  }
  if (c.on()) fail("Cannot turn cutter radius comp on when on", column);
  CompSide side = code == 410 || code == 411 ? CompSide::left : CompSide::right;
  const std::string name = "G" + std::to_string(code / 10);
  double radius = 0;
  int orientation = 0;
  if (code == 411 || code == 421) {
    if (!block.has('d')) fail(name + ".1 with no D word", column);
    radius = block.get('d') / 2.0;
    if (block.has('l')) {
      if (s.modal_.plane != Plane::xz) {
        fail(name + ".1 with L word, but plane is not G18", block.col('l'));
      }
      orientation = to_int(block.get('l'));
    }
  } else {
    const ToolEntry* entry = s.tools_.find(s.tool_in_spindle_);
    if (block.has('d')) {
      const double d = block.get('d');
      const double whole = std::round(d);
      if (std::fabs(d - whole) >= 0.0001 || whole < 0.0) {
        fail(name + " requires D word to be a whole number", block.col('d'));
      }
      const int tool = to_int(whole);
      // D0 is the tool in the spindle, as no D is (LinuxCNC's table slot 0).
      if (tool != 0) entry = s.tools_.find(tool);
      if (entry == nullptr && tool != 0 && !s.options_.tool_table.empty()) {
        fail("Requested tool " + std::to_string(tool) + " not found in the tool table",
             block.col('d'));
      }
    }
    if (entry != nullptr) {
      radius = table_length(entry->diameter, s.tool_table_units(), s.modal_.units) / 2.0;
      orientation = entry->orientation;
    }
    if (s.modal_.plane != Plane::xz && orientation != 0 && orientation != 9) {
      fail(name + " with lathe tool, but plane is not G18", column);
    }
  }
  if (radius < 0.0) {
    // A negative diameter (a tool smaller than the one the path was drawn for) cuts on the
    // other side.
    radius = -radius;
    side = side == CompSide::left ? CompSide::right : CompSide::left;
  }
  s.emit_comment(side == CompSide::right ? "interpreter: cutter radius compensation on right"
                                         : "interpreter: cutter radius compensation on left");
  c.radius = radius;
  c.orientation = orientation;
  c.side = side;
  s.parameters_.hide_position(true);
}

void Interpreter::Impl::Comp::comp_mode(Impl& s, int code) {
  if (code == 400) {
    comp_off(s);
  } else {
    comp_on(s, code);
  }
}

}  // namespace cncd::interp
