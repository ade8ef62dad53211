#include "cncd/drivers/drive_sim.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus/modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <sys/select.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace cncd::drivers {
namespace {

modbus_t* as_ctx(void* p) {
  return static_cast<modbus_t*>(p);
}

// A pseudo-terminal master with its slave side kept open, so the master never reads EIO while
// no client has the terminal open.
int open_pty(std::string& slave_path, int& keep_open) {
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return -1;
  const char* name = ptsname(master);
  if (name == nullptr) return -1;
  slave_path = name;
  keep_open = open(name, O_RDWR | O_NOCTTY);
  return master;
}

}  // namespace

DriveSim::DriveSim(DriveSimOptions options) : options_(std::move(options)), lag_s_(options_.lag_s) {
  options_.drives = std::clamp(options_.drives, 1, kDriveSimMaxDrives);
}

DriveSim::~DriveSim() {
  stop();
}

DriveSim::Drive* DriveSim::drive(int slave) noexcept {
  const int index = slave - options_.first_slave;
  if (index < 0 || index >= options_.drives) return nullptr;
  return &drives_[static_cast<std::size_t>(index)];
}

const DriveSim::Drive* DriveSim::drive(int slave) const noexcept {
  return const_cast<DriveSim*>(this)->drive(slave);
}

std::string DriveSim::start() {
  mapping_ = modbus_mapping_new(0, 0, 3, 3);
  if (options_.rtu) {
    int keep_a = -1;
    int keep_b = -1;
    master_a_ = open_pty(server_device_, keep_a);
    master_b_ = open_pty(device_, keep_b);
    if (master_a_ < 0 || master_b_ < 0) return std::string("cannot create a pseudo-terminal");
    ctx_ = modbus_new_rtu(server_device_.c_str(), 115200, 'N', 8, 1);
    if (ctx_ == nullptr || modbus_connect(as_ctx(ctx_)) != 0) {
      return "cannot open " + server_device_ + ": " + modbus_strerror(errno);
    }
    // libmodbus has its own descriptor now; the helper ones may go once the client side stays
    // referenced by keep_b until stop().
    close(keep_a);
    listen_fd_ = keep_b;
    modbus_set_slave(as_ctx(ctx_), options_.first_slave);
    running_ = true;
    relay_thread_ = std::thread([this] { relay(); });
    thread_ = std::thread([this] { serve_rtu(); });
    raise_priority(relay_thread_);
    raise_priority(thread_);
    return "";
  }
  ctx_ = modbus_new_tcp(options_.address.c_str(), options_.port);
  if (ctx_ == nullptr) return "cannot create a Modbus TCP server";
  listen_fd_ = modbus_tcp_listen(as_ctx(ctx_), 8);
  if (listen_fd_ < 0) {
    return "cannot listen on " + options_.address + ":" + std::to_string(options_.port) + ": " +
           modbus_strerror(errno);
  }
  sockaddr_in bound{};
  socklen_t size = sizeof bound;
  getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &size);
  port_ = ntohs(bound.sin_port);
  running_ = true;
  thread_ = std::thread([this] { serve_tcp(); });
  raise_priority(thread_);
  return "";
}

void DriveSim::stop() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
  if (relay_thread_.joinable()) relay_thread_.join();
  for (int* fd : {&listen_fd_, &master_a_, &master_b_}) {
    if (*fd >= 0) close(*fd);
    *fd = -1;
  }
  if (ctx_ != nullptr) {
    modbus_close(as_ctx(ctx_));
    modbus_free(as_ctx(ctx_));
    ctx_ = nullptr;
  }
  if (mapping_ != nullptr) modbus_mapping_free(static_cast<modbus_mapping_t*>(mapping_));
  mapping_ = nullptr;
}

void DriveSim::advance(double dt) noexcept {
  const double lag = lag_s_.load();
  const double alpha = lag > 0 ? 1.0 - std::exp(-dt / lag) : 1.0;
  for (int i = 0; i < options_.drives; ++i) {
    Drive& d = drives_[static_cast<std::size_t>(i)];
    const std::uint16_t control = d.control.load();
    const bool injected = d.injected_fault.load();
    if (injected) d.fault = true;
    if ((control & 2u) != 0 && !injected) d.fault = false;
    const bool enabled = (control & 1u) != 0 && !d.fault;
    const double target = d.target.load();
    if (enabled) d.position += (target - d.position) * alpha;
    const auto actual = static_cast<std::int32_t>(std::llround(d.position));
    const bool in_position = std::abs(target - actual) <= options_.in_position_counts;
    d.actual.store(actual);
    d.status.store(static_cast<std::uint16_t>(1u | (enabled ? 2u : 0u) | (d.fault ? 4u : 0u) |
                                              (in_position ? 8u : 0u)));
  }
}

int DriveSim::handle(void* ctx, const std::uint8_t* query, int length) {
  auto* m = static_cast<modbus_mapping_t*>(mapping_);
  const int header = modbus_get_header_length(as_ctx(ctx));
  Drive* d = drive(query[header - 1]);
  if (d == nullptr || silent_.load()) return 0;
  if (exception_.load()) {
    return modbus_reply_exception(as_ctx(ctx), query, MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS);
  }
  const auto target = static_cast<std::uint32_t>(d->target.load());
  const auto actual = static_cast<std::uint32_t>(d->actual.load());
  m->tab_registers[0] = static_cast<std::uint16_t>(target >> 16);
  m->tab_registers[1] = static_cast<std::uint16_t>(target & 0xffffu);
  m->tab_registers[2] = d->control.load();
  m->tab_input_registers[0] = static_cast<std::uint16_t>(actual >> 16);
  m->tab_input_registers[1] = static_cast<std::uint16_t>(actual & 0xffffu);
  m->tab_input_registers[2] = d->status.load();
  const int rc = modbus_reply(as_ctx(ctx), query, length, m);
  const int function = query[header];
  if (function == MODBUS_FC_WRITE_MULTIPLE_REGISTERS ||
      function == MODBUS_FC_WRITE_SINGLE_REGISTER) {
    const int address = (query[header + 1] << 8) | query[header + 2];
    if (address <= 1) d->target_writes.fetch_add(1);
    d->target.store(static_cast<std::int32_t>(
        (static_cast<std::uint32_t>(m->tab_registers[0]) << 16) | m->tab_registers[1]));
    d->control.store(m->tab_registers[2]);
  }
  return rc;
}

void DriveSim::raise_priority(std::thread& thread) noexcept {
  if (options_.rt_priority <= 0) return;
  sched_param param{};
  param.sched_priority = options_.rt_priority;
  const int error = pthread_setschedparam(thread.native_handle(), SCHED_FIFO, &param);
  if (error != 0) priority_error_ = error;
}

std::string DriveSim::warning() const {
  const int error = priority_error_;
  if (error == 0) return "";
  return "real-time priority " + std::to_string(options_.rt_priority) + " refused (" +
         std::strerror(error) + "): serving at ordinary priority";
}

void DriveSim::serve_tcp() {
  std::vector<int> clients;
  auto last = std::chrono::steady_clock::now();
  std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  while (running_.load()) {
    fd_set read_set;
    FD_ZERO(&read_set);
    FD_SET(listen_fd_, &read_set);
    int highest = listen_fd_;
    for (const int fd : clients) {
      FD_SET(fd, &read_set);
      highest = std::max(highest, fd);
    }
    timeval wait{0, 1000};
    const int ready = select(highest + 1, &read_set, nullptr, nullptr, &wait);
    const auto now = std::chrono::steady_clock::now();
    advance(std::chrono::duration<double>(now - last).count());
    last = now;
    if (ready <= 0) continue;
    if (FD_ISSET(listen_fd_, &read_set)) {
      const int fd = accept(listen_fd_, nullptr, nullptr);
      if (fd >= 0) clients.push_back(fd);
    }
    for (auto it = clients.begin(); it != clients.end();) {
      if (!FD_ISSET(*it, &read_set)) {
        ++it;
        continue;
      }
      modbus_set_socket(as_ctx(ctx_), *it);
      const int length = modbus_receive(as_ctx(ctx_), query);
      if (length > 0) handle(ctx_, query, length);
      if (length < 0) {
        close(*it);
        it = clients.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const int fd : clients)
    close(fd);
  modbus_set_socket(as_ctx(ctx_), -1);
}

void DriveSim::serve_rtu() {
  auto last = std::chrono::steady_clock::now();
  std::uint8_t query[MODBUS_RTU_MAX_ADU_LENGTH];
  const int fd = modbus_get_socket(as_ctx(ctx_));
  while (running_.load()) {
    pollfd p{fd, POLLIN, 0};
    const int ready = poll(&p, 1, 1);
    const auto now = std::chrono::steady_clock::now();
    advance(std::chrono::duration<double>(now - last).count());
    last = now;
    if (ready <= 0) continue;
    const int length = modbus_receive(as_ctx(ctx_), query);
    if (length > 0) handle(ctx_, query, length);
    if (length < 0) modbus_flush(as_ctx(ctx_));
  }
}

void DriveSim::relay() {
  std::uint8_t buffer[512];
  while (running_.load()) {
    pollfd p[2] = {{master_a_, POLLIN, 0}, {master_b_, POLLIN, 0}};
    if (poll(p, 2, 5) <= 0) continue;
    for (int i = 0; i < 2; ++i) {
      if ((p[i].revents & POLLIN) == 0) continue;
      const ssize_t n = ::read(p[i].fd, buffer, sizeof buffer);
      if (n > 0 && ::write(p[1 - i].fd, buffer, static_cast<std::size_t>(n)) < 0) continue;
    }
  }
}

void DriveSim::set_fault(int slave, bool fault) noexcept {
  if (Drive* d = drive(slave)) d->injected_fault.store(fault);
}

std::int32_t DriveSim::target(int slave) const noexcept {
  return load(slave, &Drive::target);
}

std::int32_t DriveSim::actual(int slave) const noexcept {
  return load(slave, &Drive::actual);
}

std::uint16_t DriveSim::control(int slave) const noexcept {
  return load(slave, &Drive::control);
}

std::uint16_t DriveSim::status(int slave) const noexcept {
  return load(slave, &Drive::status);
}

std::uint64_t DriveSim::target_writes(int slave) const noexcept {
  return load(slave, &Drive::target_writes);
}

}  // namespace cncd::drivers
