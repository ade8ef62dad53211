// What a panel press does in each state of the machine, the lamps each state lights, the
// override knobs' arithmetic, and which sim signals sim.set takes with which values: the
// table docs/protocol.md ("The panel") gives, checked state by state.
#include <cmath>

#include <gtest/gtest.h>

#include "panel_rules.hpp"
#include "sim_signals.hpp"

namespace cncd::daemon {
namespace {

using config::PanelInput;
using config::PanelLight;
using motion::MachineState;

PanelSituation on_idle_with_program() {
  PanelSituation s;
  s.machine = MachineState::on;
  s.program_open = true;
  return s;
}

TEST(PanelRules, CycleStartRunsStepsResumesOrSaysWhyNot) {
  PanelSituation s = on_idle_with_program();
  EXPECT_EQ(press_verdict(PanelInput::cycle_start, s).act, PanelAct::run);
  s.single_block = true;
  EXPECT_EQ(press_verdict(PanelInput::cycle_start, s).act, PanelAct::step);
  s.exec = ExecState::paused;
  EXPECT_EQ(press_verdict(PanelInput::cycle_start, s).act, PanelAct::step);
  s.single_block = false;
  EXPECT_EQ(press_verdict(PanelInput::cycle_start, s).act, PanelAct::resume);

  s.exec = ExecState::running;
  s.mode = Mode::automatic;
  PanelVerdict v = press_verdict(PanelInput::cycle_start, s);
  EXPECT_EQ(v.act, PanelAct::refused);
  EXPECT_EQ(v.why, "the program is already running");
  s.stepping = true;
  EXPECT_EQ(press_verdict(PanelInput::cycle_start, s).why, "the last step is still running");
  s.mode = Mode::mdi;
  EXPECT_EQ(press_verdict(PanelInput::cycle_start, s).why, "an MDI command is running");

  s = on_idle_with_program();
  s.program_open = false;
  v = press_verdict(PanelInput::cycle_start, s);
  EXPECT_EQ(v.act, PanelAct::refused);
  EXPECT_EQ(v.why, "no program is open");
  s.opening = true;
  EXPECT_NE(press_verdict(PanelInput::cycle_start, s).why.find("still being checked"),
            std::string::npos);
}

TEST(PanelRules, AnOpenDoorRefusesCycleStartInEveryState) {
  for (const ExecState exec : {ExecState::idle, ExecState::paused, ExecState::running}) {
    PanelSituation s = on_idle_with_program();
    s.exec = exec;
    s.door_open = true;
    const PanelVerdict v = press_verdict(PanelInput::cycle_start, s);
    EXPECT_EQ(v.act, PanelAct::refused);
    EXPECT_EQ(v.why, "the door is open: close it first");
  }
}

TEST(PanelRules, FeedHoldPausesOnlyARun) {
  PanelSituation s = on_idle_with_program();
  EXPECT_EQ(press_verdict(PanelInput::feed_hold, s).act, PanelAct::refused);
  EXPECT_EQ(press_verdict(PanelInput::feed_hold, s).why, "no program is running");
  s.exec = ExecState::running;
  EXPECT_EQ(press_verdict(PanelInput::feed_hold, s).act, PanelAct::pause);
  s.exec = ExecState::paused;
  EXPECT_EQ(press_verdict(PanelInput::feed_hold, s).why, "the program is already paused");
}

TEST(PanelRules, StopAbortsInAnyStateOfAMachineThatIsOn) {
  for (const ExecState exec : {ExecState::idle, ExecState::paused, ExecState::running}) {
    PanelSituation s = on_idle_with_program();
    s.exec = exec;
    EXPECT_EQ(press_verdict(PanelInput::stop, s).act, PanelAct::abort);
  }
}

TEST(PanelRules, InEstopAndOffOnlyResetAndMachineOnAct) {
  for (const MachineState machine : {MachineState::estop, MachineState::off}) {
    PanelSituation s = on_idle_with_program();
    s.machine = machine;
    for (const PanelInput input :
         {PanelInput::cycle_start, PanelInput::feed_hold, PanelInput::stop}) {
      const PanelVerdict v = press_verdict(input, s);
      EXPECT_EQ(v.act, PanelAct::ignored) << config::panel_input_key(input);
      EXPECT_EQ(v.why,
                machine == MachineState::estop ? "the machine is in estop" : "the machine is off");
    }
  }
  PanelSituation s;
  s.machine = MachineState::estop;
  EXPECT_EQ(press_verdict(PanelInput::reset, s).act, PanelAct::reset);
  EXPECT_EQ(press_verdict(PanelInput::machine_on, s).act, PanelAct::refused);
  EXPECT_EQ(press_verdict(PanelInput::machine_on, s).why,
            "the machine is in estop: reset it first");
  s.machine = MachineState::off;
  EXPECT_EQ(press_verdict(PanelInput::reset, s).act, PanelAct::none);
  EXPECT_EQ(press_verdict(PanelInput::machine_on, s).act, PanelAct::machine_on);
  s.machine = MachineState::on;
  EXPECT_EQ(press_verdict(PanelInput::machine_on, s).act, PanelAct::none);
}

std::uint32_t bit(PanelLight light) {
  return 1u << static_cast<unsigned>(light);
}

TEST(PanelRules, LampsFollowTheState) {
  EXPECT_EQ(panel_light_bits(MachineState::estop, false, ExecState::idle, false),
            bit(PanelLight::red));
  EXPECT_EQ(panel_light_bits(MachineState::on, true, ExecState::idle, false), bit(PanelLight::red));
  EXPECT_EQ(panel_light_bits(MachineState::on, false, ExecState::idle, false), 0u);
  EXPECT_EQ(panel_light_bits(MachineState::on, false, ExecState::running, false),
            bit(PanelLight::green) | bit(PanelLight::lamp_cycle_start));
  EXPECT_EQ(panel_light_bits(MachineState::on, false, ExecState::running, true),
            bit(PanelLight::amber) | bit(PanelLight::lamp_cycle_start));
  EXPECT_EQ(panel_light_bits(MachineState::on, false, ExecState::paused, false),
            bit(PanelLight::amber) | bit(PanelLight::lamp_feed_hold));
}

TEST(PanelRules, AnalogKnobsMapTheirRangeOntoTheOverrides) {
  EXPECT_DOUBLE_EQ(knob_override(5, 0, 10, 0, 1.5), 0.75);
  EXPECT_DOUBLE_EQ(knob_override(0, 0, 10, 0.5, 1.2), 0.5);
  EXPECT_DOUBLE_EQ(knob_override(10, 0, 10, 0.5, 1.2), 1.2);
  EXPECT_DOUBLE_EQ(knob_override(-3, 0, 10, 0, 1.5), 0.0);
  EXPECT_DOUBLE_EQ(knob_override(12, 0, 10, 0, 1.5), 1.5);
  EXPECT_DOUBLE_EQ(knob_override(3, 2, 4, 0, 1), 0.5);
  EXPECT_TRUE(std::isnan(knob_override(std::nan(""), 0, 10, 0, 1.5)));
  EXPECT_TRUE(std::isnan(knob_override(5, 10, 10, 0, 1.5)));
}

TEST(PanelRules, EncoderKnobsAddTheirCountsWithinTheRange) {
  EXPECT_NEAR(counted_override(1.0, 10, 0.01, 0, 1.5), 1.1, 1e-12);
  EXPECT_NEAR(counted_override(1.0, -30, 0.01, 0, 1.5), 0.7, 1e-12);
  EXPECT_DOUBLE_EQ(counted_override(1.45, 10, 0.01, 0, 1.5), 1.5);
  EXPECT_DOUBLE_EQ(counted_override(0.05, -10, 0.01, 0, 1.5), 0.0);
}

config::SignalAddress sim(const std::string& name) {
  config::SignalAddress a;
  EXPECT_EQ(config::parse_signal_address("sim:" + name, a), "");
  return a;
}

TEST(SimSignals, EachSimSignalOfTheIniHasItsKind) {
  config::MachineConfig config;
  config.io.flood = sim("flood");
  config.io.digital_inputs[0] = sim("door_closed");
  config.io.analog_inputs[1] = sim("level");
  config.io.digital_outputs[2] = sim("loop");
  config.io.digital_inputs[3] = sim("loop");  // back to back: the input
  config.panel.present = true;
  config.panel.inputs[static_cast<std::size_t>(PanelInput::cycle_start)] = sim("start");
  config.panel.mpg.counts = sim("wheel");
  config.panel.knobs[0].encoder.a = sim("feed_a");
  config.panel.knobs[1].analog = sim("rapid_knob");
  config.panel.lights[0] = sim("red");
  config.io.mist = config::SignalAddress{};
  const auto signals = sim_signals(config);
  const std::map<std::string, SimSignalKind> expected = {
      {"flood", SimSignalKind::output},
      {"door_closed", SimSignalKind::digital_input},
      {"level", SimSignalKind::analog_input},
      {"loop", SimSignalKind::digital_input},
      {"start", SimSignalKind::digital_input},
      {"wheel", SimSignalKind::counter},
      {"feed_a", SimSignalKind::digital_input},
      {"rapid_knob", SimSignalKind::analog_input},
      {"red", SimSignalKind::output}};
  EXPECT_EQ(signals, expected);
}

TEST(SimSignals, ValuesAreCheckedByKind) {
  using nlohmann::json;
  double v = -1;
  EXPECT_EQ(sim_value("start", SimSignalKind::digital_input, json(1), v), "");
  EXPECT_EQ(v, 1);
  EXPECT_EQ(sim_value("start", SimSignalKind::digital_input, json(0), v), "");
  EXPECT_EQ(v, 0);
  for (const json& bad : {json(2), json(0.5), json(1.0), json(-1), json(true), json("1")}) {
    const std::string error = sim_value("start", SimSignalKind::digital_input, bad, v);
    EXPECT_NE(error.find("\"start\""), std::string::npos) << bad.dump() << ": " << error;
  }
  EXPECT_EQ(sim_value("wheel", SimSignalKind::counter, json(-400), v), "");
  EXPECT_EQ(v, -400);
  EXPECT_EQ(sim_value("wheel", SimSignalKind::counter, json(4294967295u), v), "");
  EXPECT_NE(sim_value("wheel", SimSignalKind::counter, json(1.5), v), "");
  EXPECT_NE(sim_value("wheel", SimSignalKind::counter, json(4294967296LL), v), "");
  EXPECT_EQ(sim_value("knob", SimSignalKind::analog_input, json(4.25), v), "");
  EXPECT_EQ(v, 4.25);
  EXPECT_EQ(sim_value("knob", SimSignalKind::analog_input, json(7), v), "");
  EXPECT_NE(sim_value("knob", SimSignalKind::analog_input, json(nullptr), v), "");
  EXPECT_NE(sim_value("flood", SimSignalKind::output, json(1), v).find("is an output"),
            std::string::npos);
}

}  // namespace
}  // namespace cncd::daemon
