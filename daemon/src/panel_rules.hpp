// What the panel's buttons, lamps and knobs ([PANEL]) mean in each state of the machine, as
// functions of that state alone: the task (task_panel.cpp) carries out what they decide, and
// docs/protocol.md ("The panel") gives the same table.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <limits>
#include <string>

#include "cncd/config/panel_config.hpp"
#include "cncd/motion/status.hpp"
#include "task_report.hpp"

namespace cncd::daemon {

// What a press depends on.
struct PanelSituation {
  motion::MachineState machine = motion::MachineState::estop;
  ExecState exec = ExecState::idle;
  Mode mode = Mode::manual;
  bool program_open = false;
  bool opening = false;       // program.open's check is under way
  bool stepping = false;      // a step (program.step, single block) is under way or done
  bool single_block = false;  // the SINGLE_BLOCK switch is on
  bool door_open = false;     // the DOOR input is on (open)
};

enum class PanelAct {
  none,        // nothing to do, nothing to say (MACHINE_ON when on)
  ignored,     // estop or off: every button but MACHINE_ON and RESET does nothing
  refused,     // nothing done, and `why`
  run,         // program.run
  step,        // program.step: from idle the first block, from paused one more
  resume,      // program.resume
  pause,       // program.pause
  abort,       // program.abort
  machine_on,  // machine.on
  reset,       // machine.reset
};

struct PanelVerdict {
  PanelAct act = PanelAct::none;
  std::string why;  // ignored, refused: why, in words
};

// What a press of the button `input` (CYCLE_START, FEED_HOLD, STOP, MACHINE_ON, RESET) does.
PanelVerdict press_verdict(config::PanelInput input, const PanelSituation& now);

// The method a press carries out, as the event names it ("program.run").
const char* panel_act_method(PanelAct act);

// The lamps lit (bits 1 << config::PanelLight): red in estop or with a fault, amber while
// paused or a running program waits (tool change, at-speed, an input), green and the cycle
// start lamp while a program or MDI block runs, the feed hold lamp while paused.
std::uint32_t panel_light_bits(motion::MachineState machine, bool fault, ExecState exec,
                               bool waiting);

// An analog knob at `value`: ANALOG_MIN .. ANALOG_MAX map onto `low` .. `high`, beyond them the
// end; a reading that is not a number gives nothing (NaN).
double knob_override(double value, double analog_min, double analog_max, double low, double high);

// An encoder knob turned by `counts` from `current`: `per_count` each, kept within low .. high.
double counted_override(double current, std::int64_t counts, double per_count, double low,
                        double high);

// What the task remembers of the panel between its cycles (task_panel.cpp).
struct PanelMemory {
  bool primed = false;  // the counts below were taken: presses before the start are not acted on
  std::array<std::uint32_t, config::kPanelInputs> acted{};  // presses acted on, by input
  std::array<std::int64_t, config::kPanelCounters> counts{};
  double mpg_detents = 0;  // MPG_OVERRIDE = feed: detents turned, not yet whole
  std::array<double, config::kPanelAnalogs> analog{
      std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
      std::numeric_limits<double>::quiet_NaN()};  // the knob reading last applied
  // An override the knobs changed, told once the knob has rested (kSettle): not an event
  // for every period of a turn.
  std::array<std::string, config::kPanelAnalogs> knob_told{};
  std::array<std::chrono::steady_clock::time_point, config::kPanelAnalogs> knob_turned{};
  bool door_open = false;
  bool single_block = false;
  std::array<int, config::kPanelAxes> jog_wanted{};  // the jog buttons: +1, -1, 0
  std::array<int, config::kPanelAxes> jogging{};     // the jogs the buttons run: +1, -1, 0
  std::uint32_t lights = ~0u;                        // as last sent; ~0: never sent
};

}  // namespace cncd::daemon
