// The bus's spindle VFD: run, direction and speed written when they change, the drive's state
// and speed read every update, and its problems told once, in the bus's words.
#include <modbus/modbus.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>

#include "modbus_bus.hpp"
#include "modbus_detail.hpp"
#include "monotonic_clock.hpp"

namespace cncd::drivers {
namespace {

using modbus_detail::as_ctx;
using modbus_detail::is_exception;

// A VFD told to run shows its running bit within this time, or it has tripped.
constexpr std::int64_t kVfdStartNs = 1'000'000'000;

// Whether the drive keeps a read-only register among its input registers (function 4) rather
// than its holding registers (function 3).
bool input_table(config::SignalAddress::Table table) {
  return table != config::SignalAddress::Table::holding;
}

}  // namespace

void ModbusBus::vfd_problem(const char* format, ...) {
  FaultText current;
  vfd_reason_.copy(current.text.data(), current.text.size());
  if (current.text[0] != '\0') return;  // the first problem is the one to tell
  char text[kFaultReasonSize];
  const int n = std::snprintf(
      text, sizeof text, "modbus bus %d slave %d (spindle VFD): ", bus_.number, io_.vfd->slave);
  const auto used = static_cast<std::size_t>(std::clamp(n, 0, static_cast<int>(sizeof text) - 1));
  va_list args;
  va_start(args, format);
  std::vsnprintf(text + used, sizeof text - used, format, args);
  va_end(args);
  vfd_reason_.set(text);
}

bool ModbusBus::exchange_vfd(const IoCommand& command) {
  const config::SpindleConfig& v = *io_.vfd;
  modbus_t* ctx = as_ctx(ctx_);
  modbus_set_slave(ctx, v.slave);
  const SpindleCommand& sp = command.spindle;
  // A profile whose reverse command is its stop command cannot reverse: M4 stops the spindle
  // and faults rather than turn it forward.
  const bool refused = sp.enable && sp.reverse && v.command_reverse == v.command_stop;
  const int run = !sp.enable || refused ? v.command_stop
                  : sp.reverse          ? v.command_reverse
                                        : v.command_forward;
  const long scaled = std::lround(std::abs(sp.rpm) * v.speed_scale);
  const int speed = static_cast<int>(std::clamp(scaled, 0L, 65535L));
  const auto failed = [&](const char* what, int reg) {
    const int error = errno;
    count_error();
    if (error == ETIMEDOUT) {
      vfd_problem("no answer (timeout)");
    } else {
      vfd_problem("%s register %d (0x%04x): %s", what, reg, static_cast<unsigned>(reg),
                  modbus_strerror(error));
    }
    return is_exception(error);  // an exception leaves the link usable
  };
  const auto write_command = [&] {
    if (run == vfd_command_written_) return true;
    if (modbus_write_register(ctx, v.command_register, static_cast<std::uint16_t>(run)) == -1) {
      return failed("writing holding", v.command_register) && false;
    }
    if (run != v.command_stop) vfd_run_since_ns_ = monotonic_ns();
    vfd_command_written_ = run;
    return true;
  };
  const auto write_speed = [&] {
    if (speed == vfd_speed_written_) return true;
    if (modbus_write_register(ctx, v.speed_register, static_cast<std::uint16_t>(speed)) == -1) {
      return failed("writing holding", v.speed_register) && false;
    }
    vfd_speed_written_ = speed;
    return true;
  };
  // The speed before a run command, the stop before a speed: never a start at an old speed.
  const bool wrote =
      run == v.command_stop ? write_command() && write_speed() : write_speed() && write_command();
  if (!wrote) return errno != 0 && is_exception(errno);
  // The drive has the command now: what is read from here on answers it.
  const std::uint64_t reached = sp.sequence;

  std::uint16_t regs[8] = {};
  const auto read = [&](bool input, int first, int count) {
    const int n = input ? modbus_read_input_registers(ctx, first, count, regs)
                        : modbus_read_registers(ctx, first, count, regs);
    if (n == -1) failed(input ? "reading input" : "reading holding", first);
    return n != -1;
  };
  // The position first. The drive read it between the moment the request reached it and the
  // moment its answer set off: a window of a fraction of a millisecond, unless the answer was
  // slow.
  const bool has_position = v.position_register >= 0;
  if (has_position) {
    const std::int64_t sent = monotonic_ns();
    if (!read(input_table(v.position_table), v.position_register, v.position_width / 16)) {
      return is_exception(errno);
    }
    const std::int64_t earliest = sent + request_ns_;
    const std::int64_t latest = std::max(earliest, monotonic_ns() - response_ns_);
    std::uint32_t raw = regs[0];
    if (v.position_width == 32) {
      raw = v.position_high_first ? (std::uint32_t{regs[0]} << 16) | regs[1]
                                  : (std::uint32_t{regs[1]} << 16) | regs[0];
    }
    io_last_.vfd_position = vfd_position_.add(raw, earliest, latest);
  }

  // Both read-only registers in one request when they are close together in one table.
  std::uint16_t raw_speed = 0;
  std::uint16_t status = 0;
  const bool has_speed = v.actual_speed_register >= 0;
  const bool has_status = v.status_register >= 0;
  bool ok = true;
  if (has_speed && has_status && input_table(v.actual_speed_table) == input_table(v.status_table) &&
      std::abs(v.actual_speed_register - v.status_register) < 8) {
    const int first = std::min(v.actual_speed_register, v.status_register);
    const int count = std::abs(v.actual_speed_register - v.status_register) + 1;
    ok = read(input_table(v.status_table), first, count);
    raw_speed = regs[v.actual_speed_register - first];
    status = regs[v.status_register - first];
  } else {
    if (ok && has_speed) {
      ok = read(input_table(v.actual_speed_table), v.actual_speed_register, 1);
      raw_speed = regs[0];
    }
    if (ok && has_status) {
      ok = read(input_table(v.status_table), v.status_register, 1);
      status = regs[0];
    }
  }
  if (!ok) return is_exception(errno);

  const std::int64_t now = monotonic_ns();
  io_last_.vfd_time_ns = now;
  io_last_.vfd_acknowledged = reached;
  io_last_.vfd_status = status;
  io_last_.vfd_rpm = has_speed               ? raw_speed / v.speed_scale
                     : has_position          ? std::abs(io_last_.vfd_position.rps) * 60.0
                     : sp.enable && !refused ? std::abs(sp.rpm)
                                             : 0.0;
  const auto bit = [&](int n) { return n >= 0 && has_status && ((status >> n) & 1u) != 0; };
  bool fault = false;
  if (bit(v.fault_bit)) {
    fault = true;
    vfd_problem("reports a fault (status 0x%04x)", status);
  } else if (refused) {
    fault = true;
    vfd_problem("reverse (M4) asked for, but COMMAND_REVERSE is COMMAND_STOP: no reverse");
  } else if (v.running_bit >= 0 && has_status && run != v.command_stop && !bit(v.running_bit) &&
             now - vfd_run_since_ns_ > kVfdStartNs) {
    // Told to run a while ago and not running: tripped, or stopped at its own keypad.
    fault = true;
    vfd_problem("not running although told to (status 0x%04x)", status);
  }
  io_last_.vfd_fault = fault;
  if (fault) vfd_healthy_since_ns_ = 0;
  if (!fault && vfd_healthy_since_ns_ == 0) vfd_healthy_since_ns_ = now;
  return true;
}

}  // namespace cncd::drivers
