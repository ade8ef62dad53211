// Joints on Modbus TCP/RTU drives (DRIVER = modbus). Each [MODBUS_n] bus has its own I/O
// thread; the servo thread only swaps setpoints and readbacks through lock-free mailboxes, so
// a slow or dead drive makes feedback stale (a fault), never a late servo period.
//
// Faults (timeout, exception reply, lost connection, the drive's fault bit, stale feedback)
// latch: the drive gets no further setpoints and reports JointFeedback::fault until the servo
// turns the drives on again (a rising edge of JointCommand::enable), which also pulses the
// drive's fault-reset bit. The bus reconnects by itself meanwhile.
//
// The same I/O threads write `modbus:` outputs (coils, holding registers) when they change,
// read `modbus:` inputs every update, and drive a spindle VFD ([SPINDLE_0] DRIVER = modbus)
// through its command, speed, actual speed and status registers. The panel's signals go the
// same way: buttons and switches from discrete inputs or coils, counters (MPG_COUNTS, a knob's
// COUNTS) from holding or input registers, reported as 16-bit counts that wrap, analog knobs
// from registers, and lights to coils. The VFD's fault and stale
// feedback are reported as they are; the servo thread latches them.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "cncd/drivers/driver.hpp"
#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

class ModbusBus;

class ModbusDriver final : public Driver {
 public:
  ModbusDriver();
  ~ModbusDriver() override;

  std::string configure(const config::MachineConfig& machine,
                        const std::vector<int>& joints) override;
  // Non-RT: starts the bus threads and waits (up to 1 s) for a first readback, so the servo
  // starts from the drives' real positions.
  void enable() override;
  void disable() override;
  CNCD_RT void write(const JointCommand* commands, int count) noexcept override;
  CNCD_RT void read(JointFeedback* feedback, int count) noexcept override;
  // RT: hands the outputs and the spindle command to the bus threads.
  CNCD_RT void write_io(const IoCommand& command) noexcept override;
  // RT: the VFD's speed and state and the inputs, as the bus threads last read them.
  CNCD_RT void read_io(IoFeedback& feedback) noexcept override;
  // RT-safe, any thread: a joint drive's reason first, else the spindle VFD's.
  CNCD_RT bool fault_reason(char* out, std::size_t size) const noexcept override;
  // RT-safe, any thread: the failed requests and connects of all its buses.
  CNCD_RT std::uint64_t exchange_errors() const noexcept override;
  // The stale deadline of the slowest bus plus its update period.
  std::int64_t feedback_deadline_ns() const noexcept override { return deadline_ns_; }
  std::uint32_t capabilities() const noexcept override { return kCapPositionFeedback; }
  const char* name() const noexcept override { return "modbus"; }

  // Any thread: update cycles completed by the bus serving the joint at `index`.
  std::uint64_t bus_cycles(int index) const noexcept;

 private:
  struct Slot;    // a joint's drive (modbus_driver.cpp)
  struct IoSlot;  // a bus that serves signals or the spindle (modbus_driver.cpp)
  std::vector<std::unique_ptr<ModbusBus>> buses_;
  std::vector<Slot> slots_;
  std::vector<IoSlot> io_slots_;
  // The spindle (servo thread).
  bool has_at_speed_ = false;
  int at_speed_bit_ = 0;
  bool spindle_enabled_ = false;
  std::uint32_t spindle_starts_ = 0;
  std::int64_t deadline_ns_ = 0;
};

}  // namespace cncd::drivers
