#include "cncd/drivers/modbus_driver.hpp"

#include <time.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <thread>

#include "cncd/drivers/exclusive_lock.hpp"
#include "ini_lookup.hpp"
#include "modbus_bus.hpp"
#include "modbus_config.hpp"

#include "monotonic_clock.hpp"

namespace cncd::drivers {

struct ModbusDriver::Slot {
  ModbusBus* bus = nullptr;
  std::size_t drive = 0;
  double scale = 1;
  std::int64_t stale_ns = 0;
  bool enabled = false;  // servo thread: enable of the last write
  std::uint32_t reset_request = 0;
  Readback last{};  // kept when the mailbox is busy
};

struct ModbusDriver::IoSlot {
  ModbusBus* bus = nullptr;
  std::uint32_t digital_mask = 0;  // the digital inputs it reads
  std::array<bool, kMaxAnalogIo> analog{};
  std::uint64_t panel_mask = 0;  // the panel's inputs it reads
  std::array<bool, config::kPanelCounters> panel_counters{};
  std::array<bool, config::kPanelAnalogs> panel_analog{};
  bool vfd = false;
  std::int64_t stale_ns = 0;
  IoReadback last{};  // kept while the bus thread publishes
};

ModbusDriver::ModbusDriver() = default;

ModbusDriver::~ModbusDriver() {
  disable();
}

std::string ModbusDriver::configure(const config::MachineConfig& machine,
                                    const std::vector<int>& joints) {
  if (joints.size() > static_cast<std::size_t>(kMaxJoints)) return "too many joints for one driver";
  if (!machine.ini) return "needs the machine's INI file for its [MODBUS_n] settings";
  IniLookup ini(machine);
  std::map<int, std::vector<std::pair<std::size_t, DriveSettings>>> by_bus;
  slots_.assign(joints.size(), Slot{});
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const int j = joints[k];
    const std::string s = joint_section(j);
    if (!ini.has(s, "MODBUS")) ini.fail(s, "MODBUS", "missing: the number n of its [MODBUS_n]");
    if (!ini.has(s, "SLAVE")) ini.fail(s, "SLAVE", "missing: the drive's unit id");
    const int bus = static_cast<int>(ini.integer(s, "MODBUS"));
    DriveSettings d;
    d.joint = j;
    d.slave = static_cast<int>(ini.integer(s, "SLAVE"));
    d.target_register = static_cast<int>(ini.integer(s, "TARGET_REGISTER"));
    d.control_register = static_cast<int>(ini.integer(s, "CONTROL_REGISTER"));
    d.position_register = static_cast<int>(ini.integer(s, "POSITION_REGISTER"));
    d.status_register = static_cast<int>(ini.integer(s, "STATUS_REGISTER"));
    const std::string width = ini.choice(s, "REGISTER_WIDTH");
    if (width != "16" && width != "32") ini.fail(s, "REGISTER_WIDTH", "must be 16 or 32");
    d.wide = width != "16";
    const std::string order = upper(ini.choice(s, "WORD_ORDER"));
    if (order != "HIGH_FIRST" && order != "LOW_FIRST") {
      ini.fail(s, "WORD_ORDER", "must be HIGH_FIRST or LOW_FIRST");
    }
    d.high_first = order != "LOW_FIRST";
    slots_[k].scale = machine.joints[static_cast<std::size_t>(j)].scale;
    if (slots_[k].scale == 0) ini.fail(s, "SCALE", "modbus joints need SCALE (counts per unit)");
    if (!machine.ini->has_section("MODBUS_" + std::to_string(bus))) {
      ini.fail(s, "MODBUS", "no section [MODBUS_" + std::to_string(bus) + "]");
    }
    by_bus[bus].emplace_back(k, d);
  }
  if (!ini.error().empty()) return ini.error();
  std::map<int, IoSettings> io_by_bus;
  if (auto problem = collect_io(machine, io_by_bus); !problem.empty()) return problem;
  for (const auto& [number, io] : io_by_bus) {
    if (!machine.ini->has_section("MODBUS_" + std::to_string(number))) {
      return "no section [MODBUS_" + std::to_string(number) + "] for " +
             (io.vfd ? std::string("the spindle ([SPINDLE_0] MODBUS)") : "a modbus: signal");
    }
    by_bus.try_emplace(number);
  }
  has_at_speed_ = machine.spindle.at_speed_bit >= 0 && machine.spindle.status_register >= 0;
  at_speed_bit_ = std::max(0, machine.spindle.at_speed_bit);
  buses_.clear();
  io_slots_.clear();
  deadline_ns_ = 0;
  for (auto& [number, members] : by_bus) {
    BusSettings settings = read_bus(ini, number);
    if (!ini.error().empty()) return ini.error();
    settings.rt_priority = std::max(1, machine.cncd.rt_priority - 1);
    // Feedback older than a few update periods plus one slow reply is stale.
    const std::int64_t stale_ns =
        (5LL * settings.update_period_ms + 2LL * settings.timeout_ms) * 1'000'000;
    // The setpoint a fresh readback answers waited up to an update period in its mailbox.
    deadline_ns_ =
        std::max(deadline_ns_, stale_ns + std::int64_t{settings.update_period_ms} * 1'000'000);
    std::vector<DriveSettings> drives;
    for (const auto& member : members)
      drives.push_back(member.second);
    IoSettings io;
    if (auto found = io_by_bus.find(number); found != io_by_bus.end()) io = found->second;
    IoSlot io_slot;
    for (const IoPoint& p : io.points) {
      if (p.signal == IoPoint::Signal::digital_in) io_slot.digital_mask |= 1u << p.index;
      const auto n = static_cast<std::size_t>(p.index);
      if (p.signal == IoPoint::Signal::analog_in) io_slot.analog[n] = true;
      if (p.signal == IoPoint::Signal::panel_in) io_slot.panel_mask |= std::uint64_t{1} << n;
      if (p.signal == IoPoint::Signal::panel_counter) io_slot.panel_counters[n] = true;
      if (p.signal == IoPoint::Signal::panel_analog) io_slot.panel_analog[n] = true;
    }
    io_slot.vfd = io.vfd.has_value();
    io_slot.stale_ns = stale_ns;
    const bool serves_io = !io.empty();
    buses_.push_back(std::make_unique<ModbusBus>(settings, std::move(drives), std::move(io)));
    if (serves_io) {
      io_slot.bus = buses_.back().get();
      io_slots_.push_back(io_slot);
    }
    for (std::size_t i = 0; i < members.size(); ++i) {
      Slot& slot = slots_[members[i].first];
      slot.bus = buses_.back().get();
      slot.drive = i;
      slot.stale_ns = stale_ns;
    }
  }
  return "";
}

void ModbusDriver::enable() {
  for (auto& bus : buses_)
    bus->start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  for (Slot& slot : slots_) {
    Readback rb;
    while (std::chrono::steady_clock::now() < deadline) {
      if (slot.bus->get_readback(slot.drive, rb) && rb.time_ns != 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  // The VFD's first answer, too, so the spindle does not start out stale.
  for (IoSlot& slot : io_slots_) {
    while (slot.vfd && std::chrono::steady_clock::now() < deadline) {
      if (slot.bus->get_io(slot.last) && slot.last.vfd_time_ns != 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
}

void ModbusDriver::disable() {
  for (auto& bus : buses_)
    bus->stop();
}

void ModbusDriver::write(const JointCommand* commands, int count) noexcept {
  const int n = std::min(count, static_cast<int>(slots_.size()));
  for (int i = 0; i < n; ++i) {
    Slot& slot = slots_[static_cast<std::size_t>(i)];
    if (commands[i].enable && !slot.enabled) ++slot.reset_request;
    slot.enabled = commands[i].enable;
    const double counts = std::clamp(std::round(commands[i].position * slot.scale),
                                     double{std::numeric_limits<std::int32_t>::min()},
                                     double{std::numeric_limits<std::int32_t>::max()});
    slot.bus->put_setpoint(
        slot.drive, Setpoint{static_cast<std::int64_t>(counts), slot.reset_request, slot.enabled,
                             commands[i].cycle});
  }
}

void ModbusDriver::read(JointFeedback* feedback, int count) noexcept {
  const std::int64_t now = monotonic_ns();
  const int n = std::min(count, static_cast<int>(slots_.size()));
  for (int i = 0; i < n; ++i) {
    Slot& slot = slots_[static_cast<std::size_t>(i)];
    Readback rb;
    if (slot.bus->get_readback(slot.drive, rb)) slot.last = rb;
    const Readback& last = slot.last;
    JointFeedback& fb = feedback[i];
    fb = JointFeedback{};
    fb.position = static_cast<double>(last.counts) / slot.scale;
    fb.command_cycle = last.command_cycle;
    fb.previous_cycle = last.previous_cycle;
    // A fault from before the latest reset request is history until the bus has seen it.
    fb.fault = last.fault && last.reset_ack == slot.reset_request;
    fb.stale = last.time_ns == 0 || now - last.time_ns > slot.stale_ns;
  }
}

void ModbusDriver::write_io(const IoCommand& command) noexcept {
  if (command.spindle.enable && !spindle_enabled_) ++spindle_starts_;
  spindle_enabled_ = command.spindle.enable;
  for (IoSlot& slot : io_slots_)
    slot.bus->put_io(IoSetpoint{command, spindle_starts_});
}

void ModbusDriver::read_io(IoFeedback& feedback) noexcept {
  const std::int64_t now = monotonic_ns();
  for (IoSlot& slot : io_slots_) {
    slot.bus->get_io(slot.last);
    const IoReadback& rb = slot.last;
    feedback.digital = (feedback.digital & ~slot.digital_mask) | (rb.digital & slot.digital_mask);
    for (std::size_t n = 0; n < slot.analog.size(); ++n) {
      if (slot.analog[n]) feedback.analog[n] = rb.analog[n];
    }
    PanelFeedback& panel = feedback.panel;
    panel.inputs = (panel.inputs & ~slot.panel_mask) | (rb.panel_inputs & slot.panel_mask);
    for (std::size_t c = 0; c < slot.panel_counters.size(); ++c) {
      if (!slot.panel_counters[c]) continue;
      panel.counts[c] = rb.panel_counts[c];
      panel.counter_bits[c] = 16;
    }
    for (std::size_t k = 0; k < slot.panel_analog.size(); ++k) {
      if (slot.panel_analog[k]) panel.analog[k] = rb.panel_analog[k];
    }
    if (!slot.vfd) continue;
    SpindleFeedback& fb = feedback.spindle;
    fb = SpindleFeedback{};
    fb.present = true;
    fb.rpm = rb.vfd_rpm;
    fb.has_at_speed = has_at_speed_;
    fb.at_speed = has_at_speed_ && rb.vfd_fault == false && rb.vfd_time_ns != 0 &&
                  ((rb.vfd_status >> at_speed_bit_) & 1u) != 0;
    fb.fault = rb.vfd_fault;
    fb.stale = rb.vfd_time_ns == 0 || now - rb.vfd_time_ns > slot.stale_ns;
    fb.acknowledged = rb.vfd_acknowledged;
    if (rb.vfd_position.valid) {
      // Where the shaft is now, not where it was when the bus last read it.
      fb.has_position = true;
      fb.revolutions = rb.vfd_position.at(now, slot.stale_ns);
      fb.time_ns = now;
      fb.command_delay_ns = slot.bus->command_delay_ns();
    }
  }
}

bool ModbusDriver::fault_reason(char* out, std::size_t size) const noexcept {
  if (size == 0) return false;
  out[0] = '\0';
  for (const auto& bus : buses_) {
    bus->reason().copy(out, size);
    if (out[0] != '\0') return true;
  }
  for (const auto& bus : buses_) {
    bus->vfd_reason().copy(out, size);
    if (out[0] != '\0') return true;
  }
  return false;
}

std::uint64_t ModbusDriver::exchange_errors() const noexcept {
  std::uint64_t errors = 0;
  for (const auto& bus : buses_)
    errors += bus->errors();
  return errors;
}

std::uint64_t ModbusDriver::bus_cycles(int index) const noexcept {
  if (index < 0 || static_cast<std::size_t>(index) >= slots_.size()) return 0;
  return slots_[static_cast<std::size_t>(index)].bus->cycles();
}

std::vector<BusLockFile> bus_lock_files(const config::MachineConfig& machine,
                                        const std::filesystem::path& lock_dir) {
  std::vector<BusLockFile> out;
  if (!machine.ini) return out;
  std::set<int> numbers;
  IniLookup ini(machine);
  for (std::size_t j = 0; j < machine.joints.size(); ++j) {
    const std::string s = joint_section(static_cast<int>(j));
    if (machine.joints[j].driver == "modbus" && ini.has(s, "MODBUS")) {
      numbers.insert(static_cast<int>(ini.integer(s, "MODBUS")));
    }
  }
  std::map<int, IoSettings> io_by_bus;
  collect_io(machine, io_by_bus);
  for (const auto& entry : io_by_bus)
    numbers.insert(entry.first);
  // A name safe as a file name, whatever HOST or DEVICE hold.
  const auto file_name = [](std::string name) {
    for (char& c : name) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != ':') c = '_';
    }
    return name;
  };
  for (const int number : numbers) {
    if (!machine.ini->has_section("MODBUS_" + std::to_string(number))) continue;
    IniLookup bus_ini(machine);
    const BusSettings b = read_bus(bus_ini, number);
    if (!bus_ini.error().empty()) continue;  // configure() reports it
    if (b.rtu) {
      std::error_code ec;
      const auto device = std::filesystem::canonical(b.device, ec);
      const std::string real = ec ? b.device : device.string();
      out.push_back({"[" + b.section + "] (rtu " + b.device + ")",
                     lock_dir / ("cncd-modbus-rtu-" +
                                 file_name(real.substr(real.starts_with('/') ? 1 : 0)) + ".lock")});
    } else {
      const std::string place = b.host + ":" + std::to_string(b.port);
      out.push_back({"[" + b.section + "] (tcp " + place + ")",
                     lock_dir / ("cncd-modbus-tcp-" + file_name(b.host) + "-" +
                                 std::to_string(b.port) + ".lock")});
    }
  }
  return out;
}

}  // namespace cncd::drivers
