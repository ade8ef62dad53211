#include <cerrno>
#include <chrono>
#include <cstring>

#include "cncd/drivers/gpio_backend.hpp"

namespace cncd::drivers {
namespace {

// VCD identifier codes are printable characters from '!'.
char vcd_id(std::size_t output) {
  return static_cast<char>('!' + output);
}

}  // namespace

VcdBackend::VcdBackend(std::string path)
    : path_(std::move(path)), ring_(std::make_unique<Transition[]>(kRingSize)) {}

VcdBackend::~VcdBackend() {
  stop();
}

int VcdBackend::find_line(const std::string& spec, std::string& error) {
  std::string digits = spec;
  if (digits.rfind("GPIO", 0) == 0) digits = digits.substr(4);
  int line = -1;
  if (!digits.empty() && digits.size() <= 2 &&
      digits.find_first_not_of("0123456789") == std::string::npos) {
    line = std::stoi(digits);
  }
  if (line < 0 || line >= kVcdLines) {
    error = "no line '" + spec + "' on the recording chip (lines 0 .. 63 or GPIO0 .. GPIO63)";
    return -1;
  }
  return line;
}

std::string VcdBackend::request(const std::vector<GpioOutput>& outputs,
                                const std::vector<int>& inputs) {
  if (outputs.size() > static_cast<std::size_t>('~' - '!')) return "too many recorded outputs";
  outputs_ = outputs;
  inputs_ = inputs;
  last_.assign(outputs.size(), 0);
  file_ = std::fopen(path_.c_str(), "w");
  if (file_ == nullptr) return "cannot write " + path_ + ": " + std::strerror(errno);
  std::fprintf(file_, "$comment cncd step/dir outputs $end\n$timescale 1ns $end\n");
  std::fprintf(file_, "$scope module cncd $end\n");
  for (std::size_t i = 0; i < outputs_.size(); ++i) {
    std::fprintf(file_, "$var wire 1 %c %s $end\n", vcd_id(i), outputs_[i].name.c_str());
  }
  std::fprintf(file_, "$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n");
  for (std::size_t i = 0; i < outputs_.size(); ++i)
    std::fprintf(file_, "0%c\n", vcd_id(i));
  std::fprintf(file_, "$end\n");
  std::fflush(file_);
  last_time_ns_ = 0;
  return "";
}

void VcdBackend::start() {
  if (running_.exchange(true)) return;
  writer_ = std::thread([this] { writer_loop(); });
}

void VcdBackend::stop() {
  if (running_.exchange(false)) writer_.join();
  if (file_ == nullptr) return;
  drain();
  const auto lost = dropped_.load();
  if (lost > 0) {
    std::fprintf(file_, "$comment %llu transitions lost: ring full $end\n",
                 static_cast<unsigned long long>(lost));
  }
  std::fclose(file_);
  file_ = nullptr;
}

void VcdBackend::write_outputs(const std::uint8_t* levels, std::int64_t time_ns) noexcept {
  if (start_ns_ < 0) start_ns_ = time_ns;
  const std::int64_t at = time_ns - start_ns_;
  std::uint64_t head = head_.load(std::memory_order_relaxed);
  for (std::size_t i = 0; i < last_.size(); ++i) {
    const std::uint8_t level = levels[i] != 0 ? 1 : 0;
    if (level == last_[i]) continue;
    if (head - tail_.load(std::memory_order_acquire) >= kRingSize) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    last_[i] = level;
    ring_[head % kRingSize] = Transition{at, static_cast<std::uint32_t>(i), level};
    ++head;
  }
  head_.store(head, std::memory_order_release);
}

void VcdBackend::read_inputs(std::uint8_t* levels) noexcept {
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    const int line = inputs_[i];
    const bool high = line >= 0 && line < kVcdLines &&
                      input_levels_[static_cast<std::size_t>(line)].load(std::memory_order_relaxed);
    levels[i] = high ? 1 : 0;
  }
}

void VcdBackend::set_input_level(int line, bool high) noexcept {
  if (line >= 0 && line < kVcdLines) {
    input_levels_[static_cast<std::size_t>(line)].store(high, std::memory_order_relaxed);
  }
}

bool VcdBackend::pop(Transition& out) noexcept {
  const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  if (tail == head_.load(std::memory_order_acquire)) return false;
  out = ring_[tail % kRingSize];
  tail_.store(tail + 1, std::memory_order_release);
  return true;
}

void VcdBackend::drain() {
  Transition t{};
  bool wrote = false;
  while (pop(t)) {
    if (t.time_ns != last_time_ns_) {
      std::fprintf(file_, "#%lld\n", static_cast<long long>(t.time_ns));
      last_time_ns_ = t.time_ns;
    }
    std::fprintf(file_, "%u%c\n", t.level, vcd_id(t.output));
    wrote = true;
  }
  if (wrote) std::fflush(file_);
}

void VcdBackend::writer_loop() {
  while (running_.load()) {
    drain();
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

}  // namespace cncd::drivers
