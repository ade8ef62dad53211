// The modbus driver's settings from the INI and the config (not installed): the buses and
// which coils and registers carry the machine's signals, the panel's and a spindle VFD.
#include "modbus_config.hpp"

#include <algorithm>

#include "panel_wiring.hpp"

namespace cncd::drivers {
namespace {

IoTable table_of(config::SignalAddress::Table t) {
  switch (t) {
    case config::SignalAddress::Table::coil:
      return IoTable::coil;
    case config::SignalAddress::Table::holding:
      return IoTable::holding;
    case config::SignalAddress::Table::discrete:
      return IoTable::discrete;
    case config::SignalAddress::Table::input:
      return IoTable::input;
  }
  return IoTable::coil;
}

// "FILE:LINE: ADDRESS: " for a problem with a signal address.
std::string where(const config::SignalAddress& a) {
  std::string out;
  if (!a.source.file.empty()) out = a.source.file + ":" + std::to_string(a.source.line) + ": ";
  return out + a.text + ": ";
}

}  // namespace

BusSettings read_bus(IniLookup& ini, int number) {
  BusSettings b;
  b.number = number;
  b.section = "MODBUS_" + std::to_string(number);
  const std::string& s = b.section;
  const std::string transport = upper(ini.choice(s, "TRANSPORT"));
  if (transport != "TCP" && transport != "RTU") ini.fail(s, "TRANSPORT", "must be tcp or rtu");
  b.rtu = transport == "RTU";
  b.host = ini.text(s, "HOST").value_or("");
  b.port = static_cast<int>(ini.integer(s, "PORT"));
  b.device = ini.text(s, "DEVICE").value_or("");
  b.baud = static_cast<int>(ini.integer(s, "BAUD"));
  const std::string parity = upper(ini.choice(s, "PARITY"));
  if (parity != "N" && parity != "E" && parity != "O") ini.fail(s, "PARITY", "must be N, E or O");
  b.parity = parity.empty() ? 'N' : parity[0];
  b.data_bits = static_cast<int>(ini.integer(s, "DATA_BITS"));
  b.stop_bits = static_cast<int>(ini.integer(s, "STOP_BITS"));
  b.timeout_ms = static_cast<int>(ini.integer(s, "TIMEOUT_MS"));
  b.update_period_ms = static_cast<int>(ini.integer(s, "UPDATE_PERIOD_MS"));
  b.retries = static_cast<int>(ini.integer(s, "RETRIES"));
  if (!b.rtu && b.host.empty()) ini.fail(s, "HOST", "missing: TRANSPORT = tcp needs HOST");
  if (b.rtu && b.device.empty()) ini.fail(s, "DEVICE", "missing: TRANSPORT = rtu needs DEVICE");
  return b;
}

// The modbus signals and the VFD of the config, by bus; "" or the first problem.
std::string collect_io(const config::MachineConfig& machine, std::map<int, IoSettings>& by_bus) {
  using Signal = IoPoint::Signal;
  std::string problem;
  const auto add = [&](const config::SignalAddress& a, Signal signal, int index) {
    if (a.kind != config::SignalAddress::Kind::modbus) return;
    IoPoint p;
    p.signal = signal;
    p.index = index;
    p.slave = a.slave;
    p.table = table_of(a.table);
    p.address = a.address;
    if (p.output() && (p.table == IoTable::discrete || p.table == IoTable::input)) {
      if (problem.empty()) {
        problem = where(a) + "discrete inputs and input registers are read-only: use coil or hr";
      }
      return;
    }
    by_bus[a.bus].points.push_back(p);
  };
  const config::IoConfig& io = machine.io;
  add(io.flood, Signal::flood, 0);
  add(io.mist, Signal::mist, 0);
  for (int n = 0; n < kMaxDigitalIo; ++n) {
    add(io.digital_outputs[static_cast<std::size_t>(n)], Signal::digital_out, n);
    add(io.digital_inputs[static_cast<std::size_t>(n)], Signal::digital_in, n);
  }
  for (int n = 0; n < kMaxAnalogIo; ++n) {
    add(io.analog_outputs[static_cast<std::size_t>(n)], Signal::analog_out, n);
    add(io.analog_inputs[static_cast<std::size_t>(n)], Signal::analog_in, n);
  }
  const config::PanelConfig& panel = machine.panel;
  for (int i = 0; i < config::kPanelInputs; ++i)
    add(panel.inputs[static_cast<std::size_t>(i)], Signal::panel_in, i);
  const auto is_modbus = [](const config::SignalAddress& a) {
    return a.kind == config::SignalAddress::Kind::modbus;
  };
  // A counter or a knob is a number: a register, not a bit.
  const auto number = [&](const config::SignalAddress& a, Signal signal, int index) {
    if (is_modbus(a) && (a.table == config::SignalAddress::Table::coil ||
                         a.table == config::SignalAddress::Table::discrete)) {
      if (problem.empty())
        problem = where(a) + "a coil or discrete input holds no count: use hr or ir";
      return;
    }
    add(a, signal, index);
  };
  for (int c = 0; c < config::kPanelCounters; ++c) {
    const config::PanelCounterWiring& w = panel_counter_wiring(panel, c);
    for (const auto* line : {&w.a, &w.b}) {
      if (is_modbus(*line) && problem.empty()) {
        problem = where(*line) + "Modbus is too slow for an encoder's lines: wire its counter to " +
                  panel_counter_key(c) + "_COUNTS (a register)";
      }
    }
    number(w.counts, Signal::panel_counter, c);
  }
  for (int k = 0; k < config::kPanelAnalogs; ++k)
    number(panel_analog_address(panel, k), Signal::panel_analog, k);
  for (int l = 0; l < config::kPanelLights; ++l)
    add(panel.lights[static_cast<std::size_t>(l)], Signal::panel_light, l);

  const config::SpindleConfig& sp = machine.spindle;
  if (!sp.present || sp.driver != config::SpindleDriver::modbus) return problem;
  const std::string section = "[SPINDLE_0] ";
  if (sp.modbus < 0 && problem.empty()) problem = section + "MODBUS: missing, the n of [MODBUS_n]";
  if (!(sp.speed_scale > 0) && problem.empty()) {
    problem = section + "SPEED_SCALE must be positive (register value = rpm x SPEED_SCALE)";
  }
  const auto bit_ok = [](int bit) { return bit >= -1 && bit <= 15; };
  if (!(bit_ok(sp.running_bit) && bit_ok(sp.at_speed_bit) && bit_ok(sp.fault_bit)) &&
      problem.empty()) {
    problem = section + "RUNNING_BIT, AT_SPEED_BIT and FAULT_BIT are 0 .. 15, or -1 for none";
  }
  if (sp.position_register >= 0 && sp.position_scale == 0 && problem.empty()) {
    problem = section + "POSITION_REGISTER needs POSITION_SCALE (counts a revolution)";
  }
  by_bus[std::max(0, sp.modbus)].vfd = sp;
  return problem;
}

}  // namespace cncd::drivers
