// Steps of load_machine_config (not installed); each reads through the TypedReader and
// collects problems instead of stopping.
#pragma once

#include <string>
#include <string_view>

#include "cncd/config/machine_config.hpp"
#include "typed_reader.hpp"

namespace cncd::config {

// [EMC] [EMCMOT] [TASK] [RS274NGC] [EMCIO] [TRAJ] [DISPLAY] [CNCD]
void load_general(TypedReader& reader, MachineConfig& config);
// [DISPLAY] PROGRAM_PREFIX and [CNCD] PROGRAM_DIRS (LoadOptions::getenv gives $HOME for ~).
void load_program_dirs(TypedReader& reader, MachineConfig& config, const LoadOptions& options);
// [CNCD] STATE_DIR and where the parameter, tool and position files live.
void load_state_files(TypedReader& reader, MachineConfig& config, const LoadOptions& options);
// [WEB], cncd-web's keys (after load_program_dirs and load_state_files).
void load_web(TypedReader& reader, MachineConfig& config);
// [KINS], the joint map, [AXIS_L] and [JOINT_n]; fills the [TRAJ] limits left unset.
void load_motion(TypedReader& reader, MachineConfig& config);
// [SPINDLE_0] (and a warning for the [SPINDLE_n] cncd does not drive).
void load_spindle(TypedReader& reader, MachineConfig& config);
// The [CNCD] signals and USER_M_TIMEOUT, [RS274NGC] USER_M_PATH (after load_program_dirs) and
// the [EMCIO] tool change keys.
void load_io(TypedReader& reader, MachineConfig& config);
// Cross-checks between keys and sections.
void validate(TypedReader& reader, const MachineConfig& config);
// What the spindle's DRIVER needs, the directions, buses and lines of every signal address,
// and the tool change position against the soft limits (after load_motion).
void validate_io(TypedReader& reader, const MachineConfig& config);

// What a program or the spindle does with a signal (signal_address.cpp).
enum class SignalUse { digital_output, analog_output, digital_input, analog_input };
// "" when an address of that kind can serve that use, else why not.
std::string signal_use_refusal(const SignalAddress& address, SignalUse use);
// Repeated single-valued keys, and unknown keys that look like a misspelt known one.
void check_keys(TypedReader& reader);
// "; did you mean MAX_VELOCITY?" for a key that is a typo away from a known key of the
// section, else "".
std::string did_you_mean(std::string_view section, std::string_view key);
// Section names: duplicates, bad [JOINT_n] / [AXIS_L] names. False for a LinuxCNC 2.7-style
// file with numbered [AXIS_n] sections, which cannot be read as joints and axes.
bool check_sections(TypedReader& reader);

}  // namespace cncd::config
