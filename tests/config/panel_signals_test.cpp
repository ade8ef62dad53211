// The panel's signal addresses: evdev:DEVICE:CODE parsed and refused, each [PANEL] key's
// address checked for what the panel does with it, and signals shared where that is wrong.
#include <gtest/gtest.h>

#include <string>

#include "io_config_fixture.hpp"

namespace cncd::config::test {
namespace {

SignalAddress parsed(std::string_view text) {
  SignalAddress a;
  EXPECT_EQ(parse_signal_address(text, a), "") << text;
  return a;
}

std::string error_of(std::string_view text) {
  SignalAddress a;
  const std::string error = parse_signal_address(text, a);
  EXPECT_EQ(a.kind, Kind::none) << text;
  return error;
}

TEST(EvdevAddressTest, DeviceUpToTheLastColonAndTheCodeUpperCased) {
  auto a = parsed("evdev:/dev/input/by-id/usb-Contour_Design_ShuttleXpress-event-if00:BTN_4");
  EXPECT_EQ(a.kind, Kind::evdev);
  EXPECT_EQ(a.device, "/dev/input/by-id/usb-Contour_Design_ShuttleXpress-event-if00");
  EXPECT_EQ(a.code, "BTN_4");
  EXPECT_TRUE(a.given());
  // by-path names hold ':' of their own.
  a = parsed(" EVDEV:/dev/input/by-path/pci-0000:00:14.0-usb-0:2:1.0-event-kbd:key_f1 ");
  EXPECT_EQ(a.device, "/dev/input/by-path/pci-0000:00:14.0-usb-0:2:1.0-event-kbd");
  EXPECT_EQ(a.code, "KEY_F1");
  EXPECT_EQ(a.text, "EVDEV:/dev/input/by-path/pci-0000:00:14.0-usb-0:2:1.0-event-kbd:key_f1");
  EXPECT_EQ(parsed("evdev:/tmp/pendant.fifo:REL_DIAL").code, "REL_DIAL");
  EXPECT_EQ(parsed("evdev:/dev/input/event3:abs_x").code, "ABS_X");
}

TEST(EvdevAddressTest, BadOnesAreRefusedSayingWhatIsWrong) {
  const std::string usage = ": write evdev:DEVICE:CODE, e.g. evdev:/dev/input/by-id/NAME:KEY_F1";
  EXPECT_EQ(error_of("evdev:"), "missing the event code" + usage);
  EXPECT_EQ(error_of("evdev:/dev/input/event3"), "missing the event code" + usage);
  EXPECT_EQ(error_of("evdev:/dev/input/event3:"), "missing the event code" + usage);
  EXPECT_EQ(error_of("evdev::KEY_F1"), "missing the device" + usage);
  EXPECT_EQ(error_of("evdev:input/event3:KEY_F1"),
            "device 'input/event3' is not an absolute path" + usage);
  EXPECT_EQ(error_of("evdev:/dev/my pendant:KEY_F1"),
            "device '/dev/my pendant' contains a blank or control character");
  const std::string names =
      "': write a KEY_*, BTN_*, REL_* or ABS_* name of <linux/input-event-codes.h>, as evtest "
      "prints it";
  EXPECT_EQ(error_of("evdev:/dev/input/event3:KEY_F99"), "unknown event code 'KEY_F99" + names);
  EXPECT_EQ(error_of("evdev:/dev/input/event3:59"), "unknown event code '59" + names);
  EXPECT_EQ(error_of("evdev:/dev/input/event3:KEY_MAX"), "unknown event code 'KEY_MAX" + names);
}

class PanelSignalsTest : public IoConfigTest {
 protected:
  // gpio_ini() and a VCD chip, then [PANEL] at line kFirst + 2, its first key kFirst + 3.
  static constexpr int kKey = kFirst + 3;
  std::vector<std::string> refused(const std::string& keys) {
    return problems_of(gpio_ini(chip() + "[PANEL]\n" + keys));
  }
  std::vector<std::string> problem(int line, const std::string& message) const {
    return problem_at(kKey + line - 1, "[PANEL] " + message);
  }
};

constexpr std::string_view kDev = "evdev:/dev/input/by-id/usb-pendant-event-if00:";

TEST_F(PanelSignalsTest, EveryUseTakesItsKindsOfAddress) {
  const std::string dev(kDev);
  const MachineConfig c = loaded(gpio_ini(
      chip() +
      "[PANEL]\nCYCLE_START = gpio:!5\nFEED_HOLD = modbus:0:1:di:0\nSTOP = modbus:0:1:coil:1\n"
      "RESET = " +
      dev +
      "KEY_F1\nMPG_A = gpio:6\nMPG_B = gpio:7\n"
      "FEED_OVERRIDE_A = sim:fa\nFEED_OVERRIDE_B = sim:fb\n"
      "RAPID_OVERRIDE_ANALOG = modbus:0:1:ir:2\nSPINDLE_OVERRIDE_COUNTS = " +
      dev +
      "REL_DIAL\n"
      "LIGHT_RED = gpio:8\nLIGHT_AMBER = modbus:0:1:coil:9\nLIGHT_GREEN = sim:green\n"
      "[MODBUS_0]\nHOST = 127.0.0.1\n"));
  EXPECT_TRUE(c.panel.input(PanelInput::cycle_start).active_low);
  EXPECT_EQ(c.panel.mpg.b.line, "7");
  EXPECT_EQ(c.panel.knobs[2].encoder.counts.code, "REL_DIAL");
  EXPECT_EQ(c.panel.lights[1].table, Table::coil);
}

TEST_F(PanelSignalsTest, AnAddressThatCannotServeItsUseIsRefused) {
  const std::string dev(kDev);
  EXPECT_EQ(refused("CYCLE_START = " + dev + "REL_DIAL\n"),
            problem(1, "CYCLE_START: '" + dev +
                           "REL_DIAL': REL_DIAL is not a button: a button or switch is a KEY_* "
                           "or BTN_* code"));
  EXPECT_EQ(refused("FEED_HOLD = modbus:0:1:hr:3\n[MODBUS_0]\nHOST = h\n"),
            problem(1,
                    "FEED_HOLD: 'modbus:0:1:hr:3': a register is not a bit: use a discrete "
                    "input (di) or a coil"));
  EXPECT_EQ(refused("MPG_COUNTS = " + dev + "KEY_F1\n"),
            problem(1, "MPG_COUNTS: '" + dev +
                           "KEY_F1': KEY_F1 does not count: a counter is a REL_* code (a jog "
                           "dial or wheel)"));
  EXPECT_EQ(refused("MPG_COUNTS = gpio:5\n"),
            problem(1,
                    "MPG_COUNTS: 'gpio:5': a gpio line gives no count: wire an encoder to "
                    "the _A and _B keys"));
  EXPECT_EQ(refused("FEED_OVERRIDE_COUNTS = modbus:0:1:coil:3\n[MODBUS_0]\nHOST = h\n"),
            problem(1,
                    "FEED_OVERRIDE_COUNTS: 'modbus:0:1:coil:3': a bit gives no count: use an "
                    "input (ir) or holding register (hr)"));
  EXPECT_EQ(refused("MPG_A = modbus:0:1:di:1\nMPG_B = modbus:0:1:di:2\n[MODBUS_0]\nHOST = h\n"),
            (std::vector<std::string>{
                at(kKey) + ": [PANEL] MPG_A: 'modbus:0:1:di:1': a Modbus signal is read an "
                           "update period apart, far too seldom for quadrature: wire the "
                           "encoder to gpio lines, or its count to the _COUNTS key",
                at(kKey + 1) + ": [PANEL] MPG_B: 'modbus:0:1:di:2': a Modbus signal is read an "
                               "update period apart, far too seldom for quadrature: wire the "
                               "encoder to gpio lines, or its count to the _COUNTS key"}));
  EXPECT_EQ(refused("MPG_A = " + dev + "REL_DIAL\nMPG_B = sim:b\n"),
            problem(1, "MPG_A: '" + dev +
                           "REL_DIAL': an input device gives no quadrature channel: wire its "
                           "REL_* code to the _COUNTS key instead"));
  EXPECT_EQ(refused("SPINDLE_OVERRIDE_ANALOG = " + dev + "REL_X\n"),
            problem(1, "SPINDLE_OVERRIDE_ANALOG: '" + dev +
                           "REL_X': REL_X is not analog: an analog knob is an ABS_* code"));
  EXPECT_EQ(refused("FEED_OVERRIDE_ANALOG = gpio:4\n"),
            problem(1,
                    "FEED_OVERRIDE_ANALOG: 'gpio:4': a gpio line is not analog: use an input "
                    "(ir) or holding register (hr)"));
  EXPECT_EQ(refused("LIGHT_GREEN = " + dev + "KEY_F2\n"),
            problem(1, "LIGHT_GREEN: '" + dev +
                           "KEY_F2': an input device (evdev) cannot be written: use gpio, a "
                           "modbus coil or sim"));
  EXPECT_EQ(refused("LAMP_FEED_HOLD = modbus:0:1:di:3\n[MODBUS_0]\nHOST = h\n"),
            problem(1,
                    "LAMP_FEED_HOLD: 'modbus:0:1:di:3': a discrete input or input register "
                    "cannot be written: use a coil"));
}

TEST_F(PanelSignalsTest, EvdevServesOnlyThePanel) {
  EXPECT_EQ(
      problems_of(minimal_ini() + "[CNCD]\nDIGITAL_INPUT_0 = " + std::string(kDev) + "KEY_F1\n"),
      problem_at(43, "[CNCD] DIGITAL_INPUT_0: '" + std::string(kDev) +
                         "KEY_F1': an input device (evdev) is read only by [PANEL] keys"));
  EXPECT_EQ(problems_of(minimal_ini() + "[CNCD]\nFLOOD_OUTPUT = " + std::string(kDev) + "KEY_F1\n"),
            problem_at(43, "[CNCD] FLOOD_OUTPUT: '" + std::string(kDev) +
                               "KEY_F1': an input device (evdev) cannot be written: use gpio, a "
                               "modbus coil or sim"));
}

TEST_F(PanelSignalsTest, BusesChipsAndTheBaseThreadAreNeeded) {
  EXPECT_EQ(refused("STOP = modbus:3:1:di:0\n"),
            problem(1, "STOP: 'modbus:3:1:di:0': no section [MODBUS_3] in the file"));
  EXPECT_EQ(problems_of(minimal_ini() + "[PANEL]\nSTOP = gpio:5\n"),
            (std::vector<std::string>{
                at(43) + ": [PANEL] STOP: 'gpio:5': the panel's gpio lines are read in the base "
                         "thread: set [EMCMOT] BASE_PERIOD",
                at(43) + ": [PANEL] STOP: 'gpio:5': a gpio line needs [GPIO] CHIP"}));
}

TEST_F(PanelSignalsTest, APanelInputHasASignalOfItsOwn) {
  EXPECT_EQ(refused("CYCLE_START = sim:b\nFEED_HOLD = sim:b\n"),
            problem(2, "FEED_HOLD: 'sim:b': sim signal b is also [PANEL] CYCLE_START (" + at(kKey) +
                           "), an input too; a panel input has a signal of its own"));
  EXPECT_EQ(refused("MPG_A = gpio:5\nMPG_B = gpio:!5\n"),
            problem(2, "MPG_B: 'gpio:!5': gpio line 5 is also [PANEL] MPG_A (" + at(kKey) +
                           "), an input too; a panel input has a signal of its own"));
  // The gpio driver reads a line for one key.
  EXPECT_EQ(
      problems_of(gpio_ini(chip() + "ESTOP_LINE = 5\n[PANEL]\nRESET = gpio:5\n")),
      problem_at(kFirst + 4, "[PANEL] RESET: 'gpio:5': gpio line 5 is also [GPIO] ESTOP_LINE (" +
                                 at(kFirst + 2) +
                                 "), an input too; a panel input has a signal of its own"));
  EXPECT_EQ(refused("LIGHT_RED = gpio:9\nCYCLE_START = gpio:9\n"),
            problem(2, "CYCLE_START: 'gpio:9': gpio line 9 is also [PANEL] LIGHT_RED (" + at(kKey) +
                           "), an output; an input cannot share its line"));
  EXPECT_EQ(refused("LIGHT_RED = sim:l\nLIGHT_AMBER = sim:l\n"),
            problem(2, "LIGHT_AMBER: 'sim:l': sim signal l is also [PANEL] LIGHT_RED (" + at(kKey) +
                           "); an output has one driver"));
  // A program may read a panel's sim button (M66), and a sim light reads back.
  const MachineConfig c = loaded(
      gpio_ini(chip() + "[PANEL]\nCYCLE_START = sim:go\nLIGHT_GREEN = sim:go_lamp\n"
                        "[CNCD]\nDIGITAL_INPUT_0 = sim:go\nDIGITAL_INPUT_1 = sim:go_lamp\n"));
  EXPECT_EQ(c.io.digital_inputs[0].name, "go");
}

}  // namespace
}  // namespace cncd::config::test
