// Steps of load_machine_config (not installed); each reads through the TypedReader and
// collects problems instead of stopping.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

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
// [TELEMETRY], the job history's and cncd-telemetry's keys (after load_general).
void load_telemetry(TypedReader& reader, MachineConfig& config);
// The IP address in `text` (brackets around an IPv6 one dropped), or nullopt.
std::optional<std::string> ip_address(std::string_view text);
// [KINS], the joint map, [AXIS_L] and [JOINT_n]; fills the [TRAJ] limits left unset.
void load_motion(TypedReader& reader, MachineConfig& config);
// [SPINDLE_0] (and a warning for the [SPINDLE_n] cncd does not drive).
void load_spindle(TypedReader& reader, MachineConfig& config);
// The [CNCD] signals and USER_M_TIMEOUT, [RS274NGC] USER_M_PATH (after load_program_dirs) and
// the [EMCIO] tool change keys.
void load_io(TypedReader& reader, MachineConfig& config);
// [PANEL]: every key, the pairs that go together and the axes named (after load_general).
void load_panel(TypedReader& reader, MachineConfig& config);
// Cross-checks between keys and sections.
void validate(TypedReader& reader, const MachineConfig& config);
// What the spindle's DRIVER needs, the directions, buses and lines of every signal address,
// and the tool change position against the soft limits (after load_motion).
void validate_io(TypedReader& reader, const MachineConfig& config);

// What a program, the spindle or the panel does with a signal (signal_address.cpp). The panel
// reads buttons and switches (panel_button: digital inputs, or an input device's KEY_*/BTN_*),
// counters that wrap (modbus registers, sim, REL_*), quadrature channels (gpio, sim: decoded by
// the driver) and analog knobs (registers, sim, ABS_*); its lights are digital outputs.
enum class SignalUse {
  digital_output,
  analog_output,
  digital_input,
  analog_input,
  panel_button,
  panel_counter,
  panel_encoder,
  panel_analog
};
// A [PANEL] key that names a signal, and what the panel does with it (load_panel.cpp).
struct PanelSignal {
  std::string key;
  const SignalAddress* address;
  SignalUse use;
};
std::vector<PanelSignal> panel_signals(const PanelConfig& panel);
// "" when an address of that kind can serve that use, else why not.
std::string signal_use_refusal(const SignalAddress& address, SignalUse use);
// Repeated single-valued keys, and unknown keys that look like a misspelt known one.
void check_keys(TypedReader& reader);
// "; did you mean MAX_VELOCITY?" for a key that is a typo away from a known key of the
// section, else "".
std::string did_you_mean(std::string_view section, std::string_view key);
// A problem for each key of `section` (a section of cncd's own tools, written once) that the
// key table lacks: "unknown key in <whose>", with did_you_mean's guess.
void refuse_unknown_keys(TypedReader& reader, std::string_view section, std::string_view whose);
// Section names: duplicates, bad [JOINT_n] / [AXIS_L] names. False for a LinuxCNC 2.7-style
// file with numbered [AXIS_n] sections, which cannot be read as joints and axes.
bool check_sections(TypedReader& reader);

}  // namespace cncd::config
