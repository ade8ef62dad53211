// Turns the interpreter's canonical stream (program coordinates, program units) into machine
// coordinates and machine units in LinuxCNC canon's order:
//   machine = rotate_xy(program + g92, rotation) + g5x + tool_length_offset, then scaled to
//   machine units (linear axes only; A B C stay in degrees).
// Feed in machine units per minute. Called on the thread that runs the interpreter.
#pragma once

#include "cncd/interp/canon.hpp"

namespace cncd::interp {

class MachineTracker {
 public:
  explicit MachineTracker(Units machine_units = Units::mm) : machine_units_(machine_units) {}

  // Updates the tracked state from `command` and returns it converted: straight moves, arcs
  // (end point and center) and dwells in machine terms; other commands unchanged.
  CanonCommand to_machine(const CanonCommand& command);

  // Program pose -> machine pose with the current offsets and units.
  Pose machine_pose(const Pose& program) const;

  // Last SET_FEED_RATE in machine units per minute (units per revolution under G95),
  // converted with the program units in force when it was set.
  double feed_per_minute() const { return feed_; }
  // The tool length offset in force (G43 ... G49), machine units.
  const Pose& tool_offset() const { return tool_; }
  Units program_units() const { return program_units_; }
  Units machine_units() const { return machine_units_; }
  // Program units -> machine units.
  double length_factor() const;

 private:
  Pose to_machine_units(const Pose& program) const;

  Units machine_units_;
  Units program_units_ = Units::mm;
  // Offsets and feed in machine units.
  Pose g5x_{};
  Pose g92_{};
  Pose tool_{};
  double rotation_deg_ = 0;
  double feed_ = 0;
};

}  // namespace cncd::interp
