// What a machine's configuration tells the path from canonical commands to planned moves: the
// units the machine works in, the interpreter options its INI gives, and the axes of an arc's
// plane. One definition for the offline check, the plan simulation and the daemon's task.
#pragma once

#include <array>

#include "cncd/config/machine_config.hpp"
#include "cncd/interp/canon.hpp"
#include "cncd/interp/interpreter.hpp"

namespace cncd::pipeline {

// [TRAJ] LINEAR_UNITS as the interpreter names them.
interp::Units machine_units(const config::MachineConfig& config);

// Run from line: the height Z rises to before the other axes move ([CNCD]
// RUN_FROM_LINE_SAFE_Z, else [AXIS_Z] MAX_LIMIT), machine coordinates.
double run_from_line_safe_z(const config::MachineConfig& config);

// The interpreter options a machine's INI gives: units, tool table, parameter file, subroutine
// path, start-up code, dialect and Numeryx clearance.
interp::InterpOptions interpreter_options(const config::MachineConfig& config);

}  // namespace cncd::pipeline
