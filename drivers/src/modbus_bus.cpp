#include "modbus_bus.hpp"

#include <modbus/modbus.h>
#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "modbus_detail.hpp"
#include "monotonic_clock.hpp"
#include "panel_wiring.hpp"

namespace cncd::drivers {
namespace {

using modbus_detail::as_ctx;
using modbus_detail::is_exception;

void encode(std::int64_t counts, const DriveSettings& d, std::uint16_t* regs) {
  if (!d.wide) {
    regs[0] = static_cast<std::uint16_t>(static_cast<std::int16_t>(counts));
    return;
  }
  const auto value = static_cast<std::uint32_t>(static_cast<std::int32_t>(counts));
  const auto high = static_cast<std::uint16_t>(value >> 16);
  const auto low = static_cast<std::uint16_t>(value & 0xffffu);
  regs[0] = d.high_first ? high : low;
  regs[1] = d.high_first ? low : high;
}

std::int64_t decode(const std::uint16_t* regs, const DriveSettings& d) {
  if (!d.wide) return static_cast<std::int16_t>(regs[0]);
  const std::uint32_t high = d.high_first ? regs[0] : regs[1];
  const std::uint32_t low = d.high_first ? regs[1] : regs[0];
  return static_cast<std::int32_t>((high << 16) | low);
}

// A TCP socket whose two ends are the same address and port.
bool connected_to_itself(int fd) {
  sockaddr_storage local{};
  sockaddr_storage peer{};
  socklen_t local_size = sizeof local;
  socklen_t peer_size = sizeof peer;
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&local), &local_size) != 0 ||
      getpeername(fd, reinterpret_cast<sockaddr*>(&peer), &peer_size) != 0) {
    return false;
  }
  return local_size == peer_size && std::memcmp(&local, &peer, local_size) == 0;
}

}  // namespace

ModbusBus::ModbusBus(BusSettings bus, std::vector<DriveSettings> drives, IoSettings io)
    : bus_(std::move(bus)),
      drives_(std::move(drives)),
      setpoints_(std::make_unique<Seqlock<Setpoint>[]>(drives_.size())),
      readbacks_(std::make_unique<Seqlock<Readback>[]>(drives_.size())),
      state_(drives_.size()),
      io_(std::move(io)),
      point_written_(io_.points.size(), std::numeric_limits<double>::quiet_NaN()) {
  if (io_.vfd) {
    // Readings further apart than a few updates and a slow reply: the bus was down.
    const std::int64_t gap_ns = (4LL * bus_.update_period_ms + bus_.timeout_ms) * 1'000'000;
    // ACCELERATION is in rpm/s, the tracker wants rev/s^2.
    vfd_position_.configure(io_.vfd->position_width, io_.vfd->position_scale,
                            io_.vfd->acceleration / 60.0, gap_ns);
  }
  if (bus_.rtu && bus_.baud > 0) {
    // A read request is 8 bytes on the line, each a start bit, its data, parity and stop bits:
    // the drive reads its counter once the last of them has arrived.
    const int bits = 1 + bus_.data_bits + (bus_.parity == 'N' ? 0 : 1) + bus_.stop_bits;
    request_ns_ = 8LL * bits * 1'000'000'000 / bus_.baud;
    // The answer: address, function, byte count, the registers and the CRC.
    if (io_.vfd) {
      response_ns_ = (5LL + 2LL * io_.vfd->position_width / 16) * bits * 1'000'000'000 / bus_.baud;
    }
  }
}

ModbusBus::~ModbusBus() {
  stop();
}

void ModbusBus::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] { loop(); });
}

void ModbusBus::stop() {
  if (running_.exchange(false)) thread_.join();
  disconnect();
}

bool ModbusBus::connect() {
  modbus_t* ctx = bus_.rtu ? modbus_new_rtu(bus_.device.c_str(), bus_.baud, bus_.parity,
                                            bus_.data_bits, bus_.stop_bits)
                           : modbus_new_tcp(bus_.host.c_str(), bus_.port);
  if (ctx == nullptr) return false;
  const auto timeout_us = static_cast<std::uint32_t>(bus_.timeout_ms) * 1000u;
  modbus_set_response_timeout(ctx, timeout_us / 1'000'000u, timeout_us % 1'000'000u);
  if (modbus_connect(ctx) != 0) {
    count_error();
    modbus_free(ctx);
    return false;
  }
  if (!bus_.rtu && connected_to_itself(modbus_get_socket(ctx))) {
    // With nobody listening on a loopback port in the ephemeral range, the kernel may hand
    // the connection that very port as its source and connect it to itself. That is no drive.
    count_error();
    modbus_close(ctx);
    modbus_free(ctx);
    errno = ECONNREFUSED;
    return false;
  }
  ctx_ = ctx;
  link_failed_ = false;
  // A new connection may be a drive that restarted: every output is written once again.
  std::fill(point_written_.begin(), point_written_.end(), std::numeric_limits<double>::quiet_NaN());
  vfd_command_written_ = -1;
  vfd_speed_written_ = -1;
  return true;
}

void ModbusBus::disconnect() {
  if (ctx_ == nullptr) return;
  modbus_close(as_ctx(ctx_));
  modbus_free(as_ctx(ctx_));
  ctx_ = nullptr;
}

void ModbusBus::fail(std::size_t index, const char* what, int first, int count, bool drop_link) {
  const int error = errno;
  drop_link = drop_link && !is_exception(error);
  DriveState& s = state_[index];
  const DriveSettings& d = drives_[index];
  if (!s.latched) {
    char text[kFaultReasonSize];
    const char* why = error == ETIMEDOUT ? "timeout" : modbus_strerror(error);
    if (first < 0) {
      std::snprintf(text, sizeof text, "modbus %s slave %d (joint %d): %s", bus_.section.c_str(),
                    d.slave, d.joint, what);
    } else {
      std::snprintf(text, sizeof text, "modbus %s slave %d (joint %d): %s %d-%d: %s",
                    bus_.section.c_str(), d.slave, d.joint, what, first, first + count - 1, why);
    }
    FaultText current;
    reason_.copy(current.text.data(), current.text.size());
    if (current.text[0] == '\0' || reason_outdated_) reason_.set(text);
    reason_outdated_ = false;
  }
  s.latched = true;
  // A reply that is an exception or a fault bit leaves the link usable; anything else
  // (timeout, reset, garbage) means start over with a fresh connection.
  if (drop_link) link_failed_ = true;
}

void ModbusBus::remember_write(DriveState& s, std::uint64_t cycle) {
  // The same setpoint again: the drive has had it since it first came.
  if (s.written[0].time_ns != 0 && s.written[0].cycle == cycle) return;
  std::move_backward(s.written.begin(), s.written.end() - 1, s.written.end());
  s.written[0] = DriveState::Written{cycle, monotonic_ns()};
}

bool ModbusBus::exchange(std::size_t index, const Setpoint& setpoint) {
  const DriveSettings& d = drives_[index];
  DriveState& s = state_[index];
  modbus_t* ctx = as_ctx(ctx_);
  modbus_set_slave(ctx, d.slave);
  const int width = d.wide ? 2 : 1;
  const auto attempt = [&](auto&& request) {
    for (int tries = 0; tries <= bus_.retries; ++tries) {
      if (request() != -1) return true;
      count_error();
      if (is_exception(errno)) return false;
    }
    return false;
  };
  std::uint16_t control = 0;
  if (setpoint.enable && !s.latched) control |= kControlEnable;
  if (s.pulse_reset) control |= kControlFaultReset;
  std::uint16_t out[3] = {};
  encode(setpoint.counts, d, out);
  bool ok = true;
  if (!s.latched && d.control_register == d.target_register + width) {
    out[width] = control;
    ok = attempt([&] { return modbus_write_registers(ctx, d.target_register, width + 1, out); });
    if (!ok) fail(index, "writing holding registers", d.target_register, width + 1, true);
    if (ok) remember_write(s, setpoint.cycle);
  } else {
    if (!s.latched) {
      ok = attempt([&] { return modbus_write_registers(ctx, d.target_register, width, out); });
      if (!ok) fail(index, "writing holding registers", d.target_register, width, true);
      if (ok) remember_write(s, setpoint.cycle);
    }
    if (ok) {
      ok = attempt([&] { return modbus_write_register(ctx, d.control_register, control); });
      if (!ok) fail(index, "writing holding register", d.control_register, 1, true);
    }
  }
  if (ok) s.pulse_reset = false;
  std::uint16_t in[3] = {};
  if (ok && d.status_register == d.position_register + width) {
    ok = attempt(
        [&] { return modbus_read_input_registers(ctx, d.position_register, width + 1, in); });
    if (!ok) fail(index, "reading input registers", d.position_register, width + 1, true);
  } else if (ok) {
    ok =
        attempt([&] { return modbus_read_input_registers(ctx, d.position_register, width, in); }) &&
        attempt([&] { return modbus_read_input_registers(ctx, d.status_register, 1, in + width); });
    if (!ok) fail(index, "reading input registers", d.position_register, width, true);
  }
  if (!ok) return false;
  s.last.counts = decode(in, d);
  s.last.status = in[width];
  s.last.time_ns = monotonic_ns();
  s.last.command_cycle = s.written[0].cycle;
  // The drive has hardly begun to follow a setpoint it was just given: the one it has had a
  // whole update period to follow bounds the position from the other side.
  const std::int64_t hold_ns = std::int64_t{bus_.update_period_ms} * 1'000'000;
  for (const auto& w : s.written) {
    if (w.time_ns == 0) break;
    s.last.previous_cycle = w.cycle;
    if (s.last.time_ns - w.time_ns >= hold_ns) break;
  }
  if ((s.last.status & kStatusFault) != 0 && !s.latched) {
    fail(index, "drive reports a fault (status bit 2)", -1, 0, false);
  }
  return true;
}

// Outputs are written when they change (and once per connection); inputs are read every
// update. Digital values on registers are 0/1 (any other value reads as on); analog values on
// holding registers are rounded to the nearest integer (halves away from zero) and clamped to
// -32768 .. 65535, negative ones written as 16-bit two's complement; registers read back as
// 0 .. 65535.
bool ModbusBus::exchange_points(const IoCommand& command) {
  modbus_t* ctx = as_ctx(ctx_);
  for (std::size_t k = 0; k < io_.points.size(); ++k) {
    const IoPoint& p = io_.points[k];
    modbus_set_slave(ctx, p.slave);
    int result = 0;
    if (p.output()) {
      double value = 0;
      switch (p.signal) {
        case IoPoint::Signal::flood:
          value = command.flood ? 1 : 0;
          break;
        case IoPoint::Signal::mist:
          value = command.mist ? 1 : 0;
          break;
        case IoPoint::Signal::digital_out:
          value = (command.digital >> p.index) & 1u ? 1 : 0;
          break;
        case IoPoint::Signal::panel_light:
          value = (command.panel >> p.index) & 1u ? 1 : 0;
          break;
        default:
          value = std::clamp(std::round(command.analog[static_cast<std::size_t>(p.index)]),
                             -32768.0, 65535.0);
          break;
      }
      if (point_written_[k] == value) continue;
      if (p.table == IoTable::coil) {
        result = modbus_write_bit(ctx, p.address, value != 0 ? 1 : 0);
      } else {
        const auto reg = static_cast<std::uint16_t>(static_cast<std::int32_t>(value));
        result = modbus_write_register(ctx, p.address, reg);
      }
      if (result != -1) point_written_[k] = value;
    } else {
      std::uint8_t bit = 0;
      std::uint16_t reg = 0;
      const bool bits = p.table == IoTable::coil || p.table == IoTable::discrete;
      if (bits) {
        const auto read = p.table == IoTable::coil ? modbus_read_bits : modbus_read_input_bits;
        result = read(ctx, p.address, 1, &bit);
      } else {
        const auto read =
            p.table == IoTable::holding ? modbus_read_registers : modbus_read_input_registers;
        result = read(ctx, p.address, 1, &reg);
      }
      if (result != -1) {
        const double value = bits ? bit : reg;
        const auto n = static_cast<std::size_t>(p.index);
        switch (p.signal) {
          case IoPoint::Signal::digital_in: {
            const std::uint32_t mask = 1u << p.index;
            io_last_.digital = value != 0 ? io_last_.digital | mask : io_last_.digital & ~mask;
            break;
          }
          case IoPoint::Signal::panel_in:
            io_last_.panel_inputs = with_bit(io_last_.panel_inputs, p.index, value != 0);
            break;
          case IoPoint::Signal::panel_counter:
            io_last_.panel_counts[n] = reg;
            break;
          case IoPoint::Signal::panel_analog:
            io_last_.panel_analog[n] = value;
            break;
          default:
            io_last_.analog[n] = value;
            break;
        }
      }
    }
    if (result == -1) {
      count_error();
      if (!is_exception(errno)) return false;  // the link is gone: start over
    }
  }
  return true;
}

void ModbusBus::exchange_io(bool connected) {
  // While the servo thread is storing, the previous outputs stay.
  io_setpoint_.try_load(io_latest_);
  const IoSetpoint& setpoint = io_latest_;
  if (setpoint.spindle_starts != vfd_starts_seen_) {
    // A new start after a fault: the old reason is history.
    vfd_starts_seen_ = setpoint.spindle_starts;
    vfd_reason_.clear();
  }
  bool ok = connected && !link_failed_;
  if (!connected && io_.vfd) {
    vfd_problem(bus_.rtu ? "cannot open the serial line" : "cannot connect");
  }
  if (ok) {
    errno = 0;
    ok = exchange_points(setpoint.command);
    if (ok && io_.vfd) ok = exchange_vfd(setpoint.command);
    if (!ok) link_failed_ = true;
  }
  if (!ok) vfd_healthy_since_ns_ = 0;
  // Long healthy again: whoever saw the fault or silence has read why by now.
  const std::int64_t stale_ns = (5LL * bus_.update_period_ms + 2LL * bus_.timeout_ms) * 1'000'000;
  if (vfd_healthy_since_ns_ != 0 && monotonic_ns() - vfd_healthy_since_ns_ > 2 * stale_ns) {
    vfd_reason_.clear();
  }
  io_readback_.store(io_last_);
}

void ModbusBus::loop() {
  if (bus_.rt_priority > 0) {
    // Just below the servo thread: kept waiting for the CPU by ordinary work, the bus would
    // deliver setpoints late (the drives fall behind) and readbacks late (stale feedback).
    // Refused without privileges, and then it runs at normal priority (the daemon already
    // warns about real-time scheduling).
    sched_param param{};
    param.sched_priority = bus_.rt_priority;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  }
  const std::int64_t period_ns = static_cast<std::int64_t>(bus_.update_period_ms) * 1'000'000;
  std::int64_t next_ns = monotonic_ns();
  while (running_.load(std::memory_order_relaxed)) {
    if (ctx_ != nullptr && link_failed_) disconnect();
    const bool connected = ctx_ != nullptr || connect();
    for (std::size_t i = 0; i < drives_.size(); ++i) {
      DriveState& s = state_[i];
      // While the servo thread is storing, keep the setpoint of the last update: an empty one
      // would disable the drive, send it to zero and pass for a reset request.
      setpoints_[i].try_load(s.setpoint);
      const Setpoint& setpoint = s.setpoint;
      if (setpoint.reset_request != s.reset_ack) {
        // An explicit reset (the servo turned the drives on again): forget the latched fault,
        // ask the drive to clear its own, and let setpoints through again.
        s.reset_ack = setpoint.reset_request;
        if (s.latched) s.pulse_reset = true;
        s.latched = false;
        // Once per reset, not once per drive: the reason then names the first drive that
        // fails again, not the last.
        if (setpoint.reset_request != reason_reset_) {
          reason_reset_ = setpoint.reset_request;
          reason_outdated_ = true;
        }
      }
      if (!connected) {
        if (!s.latched) {
          errno = 0;
          fail(i, bus_.rtu ? "cannot open the serial line" : "cannot connect", -1, 0, true);
        }
      } else if (!link_failed_) {
        exchange(i, setpoint);
      } else if (!s.latched) {
        fail(i, "link lost while talking to another drive", -1, 0, true);
      }
      s.last.reset_ack = s.reset_ack;
      s.last.fault = s.latched;
      readbacks_[i].store(s.last);
    }
    // No drive failed since the reset: the reason from before it is history.
    if (reason_outdated_ &&
        std::none_of(state_.begin(), state_.end(), [](const DriveState& d) { return d.latched; })) {
      reason_.clear();
      reason_outdated_ = false;
    }
    if (!io_.empty()) exchange_io(connected);
    cycles_.fetch_add(1, std::memory_order_relaxed);
    next_ns += period_ns;
    const std::int64_t now = monotonic_ns();
    // Behind by more than a period (a timeout, a reconnect): restart the schedule from now
    // rather than firing a burst of late updates.
    if (now - next_ns > period_ns) next_ns = now;
    timespec wake{static_cast<time_t>(next_ns / 1'000'000'000),
                  static_cast<long>(next_ns % 1'000'000'000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr);
  }
}

}  // namespace cncd::drivers
