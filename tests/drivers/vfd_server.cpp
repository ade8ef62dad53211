#include "vfd_server.hpp"

#include <modbus/modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>

namespace cncd::test {
namespace {

// Room for the registers of the drives under test (Delta and GS2 status words sit at 0x21xx).
constexpr int kRegisters = 0x2200;
constexpr int kBits = 0x100;

modbus_t* as_ctx(void* p) {
  return static_cast<modbus_t*>(p);
}
modbus_mapping_t* as_mapping(void* p) {
  return static_cast<modbus_mapping_t*>(p);
}

}  // namespace

VfdServer::VfdServer(VfdMap map, int slave) : map_(map), slave_(slave) {}

VfdServer::~VfdServer() {
  if (running_.exchange(false)) thread_.join();
  if (listen_fd_ >= 0) close(listen_fd_);
  if (mapping_ != nullptr) modbus_mapping_free(as_mapping(mapping_));
  if (ctx_ != nullptr) modbus_free(as_ctx(ctx_));
}

std::string VfdServer::start() {
  ctx_ = modbus_new_tcp("127.0.0.1", 0);
  if (ctx_ == nullptr) return "modbus_new_tcp failed";
  modbus_set_slave(as_ctx(ctx_), slave_);
  mapping_ = modbus_mapping_new(kBits, kBits, kRegisters, kRegisters);
  listen_fd_ = modbus_tcp_listen(as_ctx(ctx_), 4);
  if (listen_fd_ < 0) return std::string("cannot listen: ") + modbus_strerror(errno);
  sockaddr_in bound{};
  socklen_t size = sizeof bound;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &size);
  port_ = ntohs(bound.sin_port);
  running_.store(true);
  thread_ = std::thread([this] { serve(); });
  return "";
}

std::uint16_t VfdServer::holding(int address) {
  std::lock_guard lock(mutex_);
  return as_mapping(mapping_)->tab_registers[address];
}

bool VfdServer::coil(int address) {
  std::lock_guard lock(mutex_);
  return as_mapping(mapping_)->tab_bits[address] != 0;
}

void VfdServer::set_input_register(int address, std::uint16_t value) {
  std::lock_guard lock(mutex_);
  as_mapping(mapping_)->tab_input_registers[address] = value;
}

void VfdServer::set_discrete_input(int address, bool on) {
  std::lock_guard lock(mutex_);
  as_mapping(mapping_)->tab_input_bits[address] = on ? 1 : 0;
}

void VfdServer::set_holding_register(int address, std::uint16_t value) {
  std::lock_guard lock(mutex_);
  as_mapping(mapping_)->tab_registers[address] = value;
}

void VfdServer::set_coil(int address, bool on) {
  std::lock_guard lock(mutex_);
  as_mapping(mapping_)->tab_bits[address] = on ? 1 : 0;
}

int VfdServer::writes(int address) {
  std::lock_guard lock(mutex_);
  return writes_[address];
}

void VfdServer::set_fault(bool fault) {
  std::lock_guard lock(mutex_);
  fault_ = fault;
  update_model();
}

double VfdServer::revolutions(std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  if (now_ns >= model_ns_ || history_size_ == 0) {
    advance(now_ns);
    return revolutions_;
  }
  // Between two remembered moments: as the shaft turned from one to the other.
  const std::size_t n = history_.size();
  const auto at = [&](std::size_t k) -> const Past& {  // k = 0: the oldest remembered
    return history_[(history_head_ + n - history_size_ + k) % n];
  };
  if (now_ns <= at(0).time_ns) return at(0).revolutions;
  std::size_t lo = 0;
  std::size_t hi = history_size_ - 1;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (at(mid).time_ns <= now_ns ? lo : hi) = mid;
  }
  const Past& a = at(lo);
  const Past& b = at(hi);
  if (now_ns >= b.time_ns) return b.revolutions;
  const double f =
      static_cast<double>(now_ns - a.time_ns) / static_cast<double>(b.time_ns - a.time_ns);
  return a.revolutions + f * (b.revolutions - a.revolutions);
}

std::vector<double> VfdServer::turning_points() {
  std::lock_guard lock(mutex_);
  return turns_;
}

double VfdServer::rpm(std::int64_t now_ns) {
  std::lock_guard lock(mutex_);
  advance(now_ns);
  return rpm_;
}

std::vector<VfdServer::AtSpeed> VfdServer::at_speed_log() {
  std::lock_guard lock(mutex_);
  return at_speed_log_;
}

void VfdServer::advance(std::int64_t now) {
  if (!ramps()) return;
  if (model_ns_ == 0 || now <= model_ns_) {
    if (model_ns_ == 0) model_ns_ = now;
  } else {
    // In steps of at most 100 us, the speed ramping toward its target.
    const double accel = map_.acceleration_rpm_s;
    while (model_ns_ < now) {
      const std::int64_t step = std::min<std::int64_t>(now - model_ns_, 100'000);
      const double dt = static_cast<double>(step) / 1e9;
      const double before = rpm_;
      rpm_ = accel <= 0           ? target_rpm_
             : rpm_ < target_rpm_ ? std::min(target_rpm_, rpm_ + accel * dt)
                                  : std::max(target_rpm_, rpm_ - accel * dt);
      revolutions_ += 0.5 * (before + rpm_) / 60.0 * dt;
      // Once a point: a shaft that rests, then turns back, turned back there.
      const bool again = !turns_.empty() && std::abs(turns_.back() - revolutions_) < 1e-3;
      if (((before != 0 && rpm_ == 0) || before * rpm_ < 0) && !again && turns_.size() < 64) {
        turns_.push_back(revolutions_);
      }
      model_ns_ += step;
      history_[history_head_] = Past{model_ns_, revolutions_};
      history_head_ = (history_head_ + 1) % history_.size();
      history_size_ = std::min(history_size_ + 1, history_.size());
    }
  }
  if (map_.position_register < 0) return;
  modbus_mapping_t* m = as_mapping(mapping_);
  const auto counts = static_cast<std::int64_t>(std::floor(revolutions_ * map_.counts_per_rev));
  const auto word = static_cast<std::uint64_t>(counts);
  std::uint16_t* table = map_.position_holding ? m->tab_registers : m->tab_input_registers;
  if (map_.position_width == 16) {
    table[map_.position_register] = static_cast<std::uint16_t>(word & 0xFFFFu);
  } else {
    table[map_.position_register] = static_cast<std::uint16_t>((word >> 16) & 0xFFFFu);
    table[map_.position_register + 1] = static_cast<std::uint16_t>(word & 0xFFFFu);
  }
}

void VfdServer::update_model() {
  modbus_mapping_t* m = as_mapping(mapping_);
  const int command = m->tab_registers[map_.command_register];
  const bool forward = command == map_.command_forward;
  const bool reverse = command == map_.command_reverse && !forward;
  const bool running = (forward || reverse) && !fault_;
  const std::uint16_t commanded = running ? m->tab_registers[map_.speed_register] : 0;
  // Without a shaft, the motor reaches the commanded speed at once; with one, it ramps.
  std::uint16_t speed = commanded;
  bool at_speed = running && speed > 0;
  const double target = (reverse ? -1.0 : 1.0) * commanded / map_.units_per_rpm;
  if (ramps()) {
    target_rpm_ = target;
    speed = static_cast<std::uint16_t>(std::lround(std::abs(rpm_) * map_.units_per_rpm));
    at_speed = running && commanded > 0 && rpm_ == target_rpm_;
  }
  std::uint16_t status = 0;
  if (running) status |= map_.running_bits;
  if (at_speed) status |= map_.at_speed_bits;
  if (running && reverse) status |= map_.reverse_bits;
  if (fault_) status |= map_.fault_bits;
  if (at_speed && !at_speed_ && map_.at_speed_bits != 0) {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    at_speed_log_.push_back({ts.tv_sec * 1'000'000'000LL + ts.tv_nsec, target});
  }
  at_speed_ = at_speed;
  (map_.actual_speed_holding ? m->tab_registers
                             : m->tab_input_registers)[map_.actual_speed_register] = speed;
  (map_.status_holding ? m->tab_registers : m->tab_input_registers)[map_.status_register] = status;
}

void VfdServer::serve() {
  // A drive has a processor of its own: where permitted, answer like one on a busy machine.
  sched_param param{};
  param.sched_priority = 60;
  pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  int client = -1;
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  while (running_.load()) {
    if (client < 0) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (poll(&p, 1, 10) <= 0) continue;
      client = accept(listen_fd_, nullptr, nullptr);
      continue;
    }
    pollfd p{client, POLLIN, 0};
    if (poll(&p, 1, 10) <= 0) continue;
    modbus_set_socket(as_ctx(ctx_), client);
    const int n = modbus_receive(as_ctx(ctx_), query);
    if (n < 0) {
      close(client);
      client = -1;
      continue;
    }
    if (n == 0 || silent_.load()) continue;
    const int header = modbus_get_header_length(as_ctx(ctx_));
    const int function = query[header];
    const int address = (query[header + 1] << 8) | query[header + 2];
    std::lock_guard lock(mutex_);
    // The drive answers with its shaft where it is as the request arrives.
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    advance(ts.tv_sec * 1'000'000'000LL + ts.tv_nsec);
    update_model();
    if (function == 0x05 || function == 0x06 || function == 0x0F || function == 0x10) {
      ++writes_[address];
    }
    modbus_reply(as_ctx(ctx_), query, n, as_mapping(mapping_));
    update_model();
    answered_.fetch_add(1);
  }
  if (client >= 0) close(client);
}

}  // namespace cncd::test
