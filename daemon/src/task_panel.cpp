// The panel ([PANEL]) on the task's side: the presses, switches, jog buttons and knobs the servo
// thread has debounced and counted (motion::PanelStatus), carried out as the operator's
// commands are, each told by a "command" event by "panel"; and its lamps. The MPG's jogs are
// the servo thread's own.
#include <cmath>

#include <fmt/format.h>

#include "task.hpp"

namespace cncd::daemon {

namespace {

using config::PanelInput;
using Clock = std::chrono::steady_clock;

// A knob's override change is told once the knob has rested this long.
constexpr auto kKnobSettle = std::chrono::milliseconds(300);

std::size_t index_of(PanelInput input) {
  return static_cast<std::size_t>(input);
}

PanelInput offset(PanelInput first, int axis) {
  return static_cast<PanelInput>(static_cast<int>(first) + axis);
}

std::string axis_name(int axis) {
  return std::string(1, config::kAxisLetters[static_cast<std::size_t>(axis)]);
}

// Events added while it lives are by the panel.
class PanelActor {
 public:
  explicit PanelActor(EventLog& events) : events_(events), before_(events.actor()) {
    events_.set_actor("panel");
  }
  ~PanelActor() { events_.set_actor(before_); }
  PanelActor(const PanelActor&) = delete;
  PanelActor& operator=(const PanelActor&) = delete;

 private:
  EventLog& events_;
  std::string before_;
};

}  // namespace

bool Task::panel_wired(PanelInput input) const {
  return config_.panel.present && config_.panel.input(input).given();
}

bool Task::panel_level(PanelInput input, const motion::Status& status) const {
  return panel_wired(input) && ((status.panel.inputs >> index_of(input)) & 1u) != 0;
}

bool Task::door_open(const motion::Status& status) const {
  return panel_level(PanelInput::door, status);
}

void Task::refuse_if_door_open() const {
  if (door_open(motion_.status()))
    throw TaskError(TaskErrorKind::wrong_state, "the door is open ([PANEL] DOOR): close it first");
}

void Task::poll_panel(const motion::Status& status) {
  if (status.motion != motion::MotionState::jogging) {
    client_jog_axes_ = 0;
    panel_.jogging = {};
  }
  if (!config_.panel.present) return;
  const PanelActor by(events_);
  if (!panel_.primed) {
    panel_.acted = status.panel.presses;
    panel_.counts = status.panel.counts;
    panel_.primed = true;
  }
  panel_door(status);
  // A stop or a hold acts before a start pressed since the last cycle.
  for (const PanelInput input : {PanelInput::stop, PanelInput::feed_hold, PanelInput::reset,
                                 PanelInput::machine_on, PanelInput::cycle_start}) {
    const std::size_t i = index_of(input);
    if (status.panel.presses[i] == panel_.acted[i]) continue;
    panel_.acted[i] = status.panel.presses[i];
    if (panel_wired(input)) panel_press(input);
  }
  const motion::Status now = motion_.status();
  panel_switches(now);
  panel_jogs(now);
  panel_knobs(now);
  panel_lights(now);
}

void Task::panel_press(PanelInput input) {
  const motion::Status status = motion_.status();
  PanelSituation now;
  now.machine = status.machine;
  now.exec = exec_;
  now.mode = mode_;
  now.program_open = !program_path_.empty();
  now.opening = opening_.has_value();
  now.stepping = stepping_;
  now.single_block = panel_level(PanelInput::single_block, status);
  now.door_open = door_open(status);
  const PanelVerdict verdict = press_verdict(input, now);
  const std::string key = config::panel_input_key(input);
  switch (verdict.act) {
    case PanelAct::none:
      return;
    case PanelAct::ignored:
      events_.add("info", "command", key + " ignored: " + verdict.why);
      return;
    case PanelAct::refused:
      events_.add("warning", "command", key + " refused: " + verdict.why);
      return;
    default:
      break;
  }
  std::string what = key + ": " + panel_act_method(verdict.act);
  try {
    switch (verdict.act) {
      case PanelAct::run:
        run_program();
        break;
      case PanelAct::step:
        step();
        break;
      case PanelAct::resume:
        resume();
        break;
      case PanelAct::pause:
        if (const PauseWaitReport wait = pause(); !wait.kind.empty()) what += ": " + wait.message;
        break;
      case PanelAct::abort:
        abort();
        break;
      case PanelAct::machine_on:
        machine_on(kPanelToken);
        break;
      case PanelAct::reset:
        reset();
        break;
      default:
        break;
    }
  } catch (const TaskError& e) {
    events_.add("warning", "command", what + ": refused: " + e.what());
    return;
  }
  events_.add("info", "command", what);
}

void Task::panel_door(const motion::Status& status) {
  if (!panel_wired(PanelInput::door)) return;
  const bool open = door_open(status);
  if (open == panel_.door_open) return;
  panel_.door_open = open;
  if (!open) {
    events_.add("info", "command", "DOOR closed");
    return;
  }
  if (status.machine != motion::MachineState::on) {
    events_.add("info", "command",
                std::string("DOOR opened: the machine is ") + machine_state_name(status.machine));
    return;
  }
  if (config_.panel.door_mode == config::PanelConfig::DoorMode::estop) {
    estop();
    events_.add("warning", "command", "DOOR opened: machine.estop");
    return;
  }
  std::string what = "DOOR opened: ";
  if (exec_ == ExecState::running) {
    pause();
    what += "program.pause, then ";
  }
  // A program held comes back with its spindle and coolant on resume; without one they stay
  // off, as M5 M9 would leave them.
  motion_.hold_io_at_rest(exec_ != ExecState::idle);
  events_.add("warning", "command", what + "the spindle and the coolant stop at rest");
}

void Task::panel_switches(const motion::Status& status) {
  const bool single = panel_level(PanelInput::single_block, status);
  if (single && !panel_.single_block && exec_ == ExecState::running && mode_ == Mode::automatic &&
      !stepping_) {
    // Switched on mid-run: the run pauses once the blocks already read are carried out.
    stepping_ = true;
    runner_->single_step(true, 0);
    events_.add("info", "command", "SINGLE_BLOCK on: the program pauses after this block");
  }
  panel_.single_block = single;
  // Unwired, M1 always stops and block delete is the interpreter's default.
  runner_->feeder().set_optional_stop(!panel_wired(PanelInput::optional_stop) ||
                                      panel_level(PanelInput::optional_stop, status));
  interp_->set_block_delete(panel_wired(PanelInput::block_delete)
                                ? panel_level(PanelInput::block_delete, status)
                                : interp::InterpOptions{}.block_delete);
}

std::string Task::panel_jog_refusal(const motion::Status& status) const {
  if (exec_ != ExecState::idle) return "a program or MDI block is running";
  const auto holder = manual_holder(status);
  // The panel's own buttons share the one hand at the machine.
  if (holder && (!holder->panel || status.panel.mpg_jogging)) return holder->by + " is jogging";
  return "";
}

void Task::panel_jogs(const motion::Status& status) {
  const bool on = status.machine == motion::MachineState::on;
  for (int axis = 0; axis < config::kPanelAxes; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    if (!config_.axes[a].present) continue;
    const PanelInput plus = offset(PanelInput::jog_plus_x, axis);
    const PanelInput minus = offset(PanelInput::jog_minus_x, axis);
    // Both held: neither.
    const int wanted = (panel_level(plus, status) ? 1 : 0) - (panel_level(minus, status) ? 1 : 0);
    if (wanted == panel_.jog_wanted[a]) continue;
    panel_.jog_wanted[a] = wanted;
    if (!on) {
      panel_.jogging[a] = 0;
      continue;
    }
    if (panel_.jogging[a] != 0) {
      jog_stop(axis);
      events_.add("info", "command",
                  config::panel_input_key(panel_.jogging[a] > 0 ? plus : minus) +
                      " released: jog.stop " + axis_name(axis));
      panel_.jogging[a] = 0;
    }
    if (wanted == 0) continue;
    const std::string key = config::panel_input_key(wanted > 0 ? plus : minus);
    const double speed = std::min(config_.default_linear_velocity, config_.axes[a].max_velocity);
    std::string refusal = panel_jog_refusal(motion_.status());
    if (refusal.empty()) refusal = motion_.jog_start(axis, wanted * speed);
    if (!refusal.empty()) {
      events_.add("warning", "command",
                  key + ": jog.start " + axis_name(axis) + ": refused: " + refusal);
      continue;
    }
    panel_.jogging[a] = wanted;
    events_.add(
        "info", "command",
        fmt::format("{}: jog.start {} at {:g} units/s", key, axis_name(axis), wanted * speed));
  }
}

void Task::panel_knobs(const motion::Status& status) {
  const bool on = status.machine == motion::MachineState::on;
  const auto now = Clock::now();
  static constexpr const char* kNames[] = {"FEED_OVERRIDE", "RAPID_OVERRIDE", "SPINDLE_OVERRIDE"};
  static constexpr const char* kMethods[] = {"override.feed", "override.rapid", "override.spindle"};
  const double lows[] = {0.0, 0.0, config_.min_spindle_override};
  const double highs[] = {config_.max_feed_override, 1.0, config_.max_spindle_override};
  double current[] = {status.feed_override, status.rapid_override, status.spindle.override_ratio};
  const auto set = [&](std::size_t k, double ratio) {
    if (ratio == current[k]) return;
    current[k] = ratio;
    if (k == 0) set_feed_override(ratio);
    if (k == 1) set_rapid_override(ratio);
    if (k == 2) set_spindle_override(ratio);
    panel_.knob_told[k] =
        fmt::format("{}: {} {:g} ({:g} %)", kNames[k], kMethods[k], ratio, ratio * 100.0);
    panel_.knob_turned[k] = now;
  };
  const auto& counts = status.panel.counts;
  for (std::size_t k = 0; k < config_.panel.knobs.size(); ++k) {
    const config::OverrideKnob& knob = config_.panel.knobs[k];
    const std::size_t c = k + 1;  // PanelCounter: the mpg, then the knobs
    const std::int64_t turned = counts[c] - panel_.counts[c];
    panel_.counts[c] = counts[c];
    if (!on) continue;
    if (knob.encoder.given() && turned != 0)
      set(k, counted_override(current[k], turned, knob.per_count, lows[k], highs[k]));
    const double reading = status.panel.analog[k];
    if (knob.analog.given() && !(reading == panel_.analog[k])) {
      panel_.analog[k] = reading;
      const double ratio =
          knob_override(reading, knob.analog_min, knob.analog_max, lows[k], highs[k]);
      if (std::isfinite(ratio)) set(k, ratio);
    }
  }
  // MPG_OVERRIDE = feed: while a program runs the wheel turns the feed override, a detent a
  // FEED_OVERRIDE_SCALE step.
  const std::int64_t wheel = counts[0] - panel_.counts[0];
  panel_.counts[0] = counts[0];
  if (config_.panel.mpg_override_feed && on && exec_ == ExecState::running &&
      mode_ == Mode::automatic && wheel != 0) {
    panel_.mpg_detents +=
        static_cast<double>(wheel) / std::max(1, config_.panel.mpg_counts_per_detent);
    const double whole = std::trunc(panel_.mpg_detents);
    panel_.mpg_detents -= whole;
    if (whole != 0) {
      set(0, counted_override(current[0], static_cast<std::int64_t>(whole),
                              config_.panel.knobs[0].per_count, lows[0], highs[0]));
    }
  } else if (exec_ == ExecState::idle) {
    panel_.mpg_detents = 0;
  }
  for (std::size_t k = 0; k < panel_.knob_told.size(); ++k) {
    if (panel_.knob_told[k].empty() || now - panel_.knob_turned[k] < kKnobSettle) continue;
    events_.add("info", "command", panel_.knob_told[k]);
    panel_.knob_told[k].clear();
  }
}

void Task::panel_lights(const motion::Status& status) {
  const bool waiting = status.wait.kind != motion::WaitStatus::Kind::none;
  const std::uint32_t bits =
      panel_light_bits(status.machine, status.fault_reason[0] != '\0', exec_, waiting);
  if (bits == panel_.lights) return;
  motion_.set_panel_lights(bits);
  panel_.lights = bits;
}

PanelReport Task::panel_report(const motion::Status& status) const {
  PanelReport out;
  for (int i = 0; i < config::kPanelInputs; ++i) {
    const auto input = static_cast<PanelInput>(i);
    if (panel_wired(input))
      out.inputs.emplace_back(config::panel_input_key(input), panel_level(input, status));
  }
  for (int i = 0; i < config::kPanelLights; ++i) {
    const auto light = static_cast<config::PanelLight>(i);
    out.lights.emplace_back(std::string(config::panel_light_key(light)),
                            ((status.panel.lights >> i) & 1u) != 0);
  }
  out.mpg_axis = status.panel.mpg_axis;
  out.mpg_step = status.panel.mpg_step;
  out.mpg_counts = status.panel.counts[static_cast<std::size_t>(config::PanelCounter::mpg)];
  out.mpg_jogging = status.panel.mpg_jogging;
  out.door = door_open(status);
  out.single_block = panel_level(PanelInput::single_block, status);
  out.optional_stop = runner_->feeder().optional_stop();
  out.block_delete = panel_wired(PanelInput::block_delete)
                         ? panel_level(PanelInput::block_delete, status)
                         : interp::InterpOptions{}.block_delete;
  return out;
}

}  // namespace cncd::daemon
