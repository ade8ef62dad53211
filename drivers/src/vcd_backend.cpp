#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>

#include "cncd/drivers/gpio_backend.hpp"

namespace cncd::drivers {
namespace {

// VCD identifier codes are printable characters from '!'.
char vcd_id(std::size_t output) {
  return static_cast<char>('!' + output);
}

}  // namespace

VcdBackend::VcdBackend(std::string path)
    : path_(std::move(path)),
      ring_(std::make_unique<Transition[]>(kRingSize)),
      feed_(std::make_unique<InputStep[]>(kFeedSize)) {}

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
                                const std::vector<GpioLine>& inputs) {
  if (outputs.size() + inputs.size() > static_cast<std::size_t>('~' - '!' + 1)) {
    return "too many recorded lines";
  }
  outputs_ = outputs;
  inputs_ = inputs;
  last_.assign(outputs.size() + inputs.size(), 0);
  file_ = std::fopen(path_.c_str(), "w");
  if (file_ == nullptr) return "cannot write " + path_ + ": " + std::strerror(errno);
  std::fprintf(file_, "$comment cncd gpio lines $end\n$timescale 1ns $end\n");
  std::fprintf(file_, "$scope module cncd $end\n");
  for (std::size_t i = 0; i < last_.size(); ++i) {
    const std::string& name =
        i < outputs_.size() ? outputs_[i].name : inputs_[i - outputs_.size()].name;
    // Every line has a name in the file: an unnamed input is called by its line.
    const std::string shown =
        name.empty() ? "in" + std::to_string(inputs_[i - outputs_.size()].line) : name;
    std::fprintf(file_, "$var wire 1 %c %s $end\n", vcd_id(i), shown.c_str());
  }
  std::fprintf(file_, "$upscope $end\n$enddefinitions $end\n#0\n$dumpvars\n");
  for (std::size_t i = 0; i < last_.size(); ++i)
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

void VcdBackend::record(std::size_t signal, std::uint8_t level, std::int64_t time_ns) noexcept {
  if (level == last_[signal]) return;
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) >= kRingSize) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  last_[signal] = level;
  ring_[head % kRingSize] =
      Transition{time_ns - start_ns_, static_cast<std::uint32_t>(signal), level};
  head_.store(head + 1, std::memory_order_release);
}

void VcdBackend::write_outputs(const std::uint8_t* levels, std::int64_t time_ns) noexcept {
  if (start_ns_ < 0) start_ns_ = time_ns;
  for (std::size_t i = 0; i < outputs_.size(); ++i)
    record(i, levels[i] != 0 ? 1 : 0, time_ns);
}

void VcdBackend::read_inputs(std::uint8_t* levels, std::int64_t time_ns) noexcept {
  if (start_ns_ < 0) start_ns_ = time_ns;
  apply_feed();
  for (std::size_t i = 0; i < inputs_.size(); ++i) {
    const int line = inputs_[i].line;
    const bool high = line >= 0 && line < kVcdLines &&
                      input_levels_[static_cast<std::size_t>(line)].load(std::memory_order_relaxed);
    levels[i] = high ? 1 : 0;
    record(outputs_.size() + i, levels[i], time_ns);
  }
}

void VcdBackend::apply_feed() noexcept {
  if (hold_left_ > 0) --hold_left_;
  const std::uint64_t head = feed_head_.load(std::memory_order_acquire);
  std::uint64_t fed = fed_.load(std::memory_order_relaxed);
  while (hold_left_ == 0 && fed < head) {
    const InputStep& step = feed_[fed % kFeedSize];
    set_input_level(step.line, step.high);
    hold_left_ = step.hold_periods;
    ++fed;
  }
  fed_.store(fed, std::memory_order_release);
}

bool VcdBackend::feed_inputs(const std::vector<InputStep>& steps) {
  const std::uint64_t head = feed_head_.load(std::memory_order_relaxed);
  if (head + steps.size() - fed_.load(std::memory_order_acquire) > kFeedSize) return false;
  for (std::size_t k = 0; k < steps.size(); ++k)
    feed_[(head + k) % kFeedSize] = steps[k];
  feed_head_.store(head + steps.size(), std::memory_order_release);
  return true;
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
