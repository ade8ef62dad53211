// The GPIO character device through libgpiod 1.6: one bulk request for the outputs and one for
// the inputs, so a base period costs one set ioctl and one get ioctl.
#include <gpiod.h>

#include <cerrno>
#include <cstring>

#include "cncd/drivers/gpio_backend.hpp"

namespace cncd::drivers {
namespace {

constexpr const char* kConsumer = "cncd";

class ChipBackend final : public GpioBackend {
 public:
  explicit ChipBackend(gpiod_chip* chip) : chip_(chip) {}
  ~ChipBackend() override {
    if (!outputs_.empty()) gpiod_line_release_bulk(&output_bulk_);
    if (!inputs_.empty()) gpiod_line_release_bulk(&input_bulk_);
    gpiod_chip_close(chip_);
  }

  int find_line(const std::string& spec, std::string& error) override {
    const bool number = !spec.empty() && spec.find_first_not_of("0123456789") == std::string::npos;
    if (number) {
      const unsigned long offset = std::strtoul(spec.c_str(), nullptr, 10);
      if (offset < gpiod_chip_num_lines(chip_)) return static_cast<int>(offset);
      error = "line " + spec + " does not exist on " + gpiod_chip_name(chip_) + " (" +
              std::to_string(gpiod_chip_num_lines(chip_)) + " lines)";
      return -1;
    }
    gpiod_line* line = gpiod_chip_find_line(chip_, spec.c_str());
    if (line == nullptr) {
      error = "no line named '" + spec + "' on " + gpiod_chip_name(chip_);
      return -1;
    }
    return static_cast<int>(gpiod_line_offset(line));
  }

  std::string request(const std::vector<GpioOutput>& outputs,
                      const std::vector<GpioLine>& inputs) override {
    if (outputs.size() > GPIOD_LINE_BULK_MAX_LINES || inputs.size() > GPIOD_LINE_BULK_MAX_LINES) {
      return "more than " + std::to_string(GPIOD_LINE_BULK_MAX_LINES) + " lines on one chip";
    }
    gpiod_line_bulk_init(&output_bulk_);
    gpiod_line_bulk_init(&input_bulk_);
    for (const auto& out : outputs) {
      gpiod_line* line = gpiod_chip_get_line(chip_, static_cast<unsigned>(out.line));
      if (line == nullptr) return "cannot get line " + std::to_string(out.line);
      gpiod_line_bulk_add(&output_bulk_, line);
    }
    for (const GpioLine& in : inputs) {
      gpiod_line* line = gpiod_chip_get_line(chip_, static_cast<unsigned>(in.line));
      if (line == nullptr) return "cannot get line " + std::to_string(in.line);
      gpiod_line_bulk_add(&input_bulk_, line);
    }
    if (!outputs.empty()) {
      const std::vector<int> low(outputs.size(), 0);
      if (gpiod_line_request_bulk_output(&output_bulk_, kConsumer, low.data()) != 0) {
        return std::string("cannot claim the output lines: ") + std::strerror(errno);
      }
      outputs_ = outputs;
    }
    if (!inputs.empty()) {
      if (gpiod_line_request_bulk_input(&input_bulk_, kConsumer) != 0) {
        return std::string("cannot claim the input lines: ") + std::strerror(errno);
      }
      inputs_ = inputs;
    }
    return "";
  }

  void write_outputs(const std::uint8_t* levels, std::int64_t /*time_ns*/) noexcept override {
    if (outputs_.empty()) return;
    int values[GPIOD_LINE_BULK_MAX_LINES];
    for (std::size_t i = 0; i < outputs_.size(); ++i)
      values[i] = levels[i];
    gpiod_line_set_value_bulk(&output_bulk_, values);
  }

  void read_inputs(std::uint8_t* levels, std::int64_t /*time_ns*/) noexcept override {
    if (inputs_.empty()) return;
    int values[GPIOD_LINE_BULK_MAX_LINES] = {};
    if (gpiod_line_get_value_bulk(&input_bulk_, values) != 0) return;
    for (std::size_t i = 0; i < inputs_.size(); ++i)
      levels[i] = values[i] != 0 ? 1 : 0;
  }

 private:
  gpiod_chip* chip_;
  gpiod_line_bulk output_bulk_{};
  gpiod_line_bulk input_bulk_{};
  std::vector<GpioOutput> outputs_;
  std::vector<GpioLine> inputs_;
};

}  // namespace

std::unique_ptr<GpioBackend> make_gpio_backend(const std::string& chip, std::string& error) {
  if (chip.rfind("vcd:", 0) == 0) {
    if (chip.size() == 4) {
      error = "vcd: needs a file name, e.g. vcd:/tmp/steps.vcd";
      return nullptr;
    }
    return std::make_unique<VcdBackend>(chip.substr(4));
  }
  gpiod_chip* handle = gpiod_chip_open_lookup(chip.c_str());
  if (handle == nullptr) {
    error = "cannot open GPIO chip '" + chip + "': " + std::strerror(errno);
    return nullptr;
  }
  return std::make_unique<ChipBackend>(handle);
}

}  // namespace cncd::drivers
