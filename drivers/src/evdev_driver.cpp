#include "cncd/drivers/evdev_driver.hpp"

#include <fcntl.h>
#include <linux/input.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <optional>

#include "cncd/config/enum_name.hpp"
#include "cncd/config/evdev_codes.hpp"
#include "evdev_reader.hpp"
#include "panel_wiring.hpp"

namespace cncd::drivers {
namespace {

using config::EvdevCode;
using config::SignalAddress;
using Target = EvdevBinding::Target;

// A press shows this much longer than the debounce time, for the servo thread's sampling and
// a late reader thread.
constexpr std::int64_t kHoldMarginNs = 50'000'000;

bool is_evdev(const SignalAddress& a) {
  return a.kind == SignalAddress::Kind::evdev;
}

// "FILE:LINE: [PANEL] KEY = ADDRESS: " for a problem with a key's address.
std::string where(const std::string& key, const SignalAddress& a) {
  std::string out;
  if (!a.source.file.empty()) out = a.source.file + ":" + std::to_string(a.source.line) + ": ";
  return out + "[PANEL] " + key + " = " +
         (a.text.empty() ? "evdev:" + a.device + ":" + a.code : a.text) + ": ";
}

const char* kind_of(EvdevCode::Type type) {
  static constexpr const char* kNames[] = {"a button (KEY_, BTN_)", "a relative axis (REL_)",
                                           "an absolute axis (ABS_)"};
  return config::enum_name(type, kNames);
}

EvdevCode::Type type_for(Target target) {
  if (target == Target::counter) return EvdevCode::Type::rel;
  return target == Target::analog ? EvdevCode::Type::abs : EvdevCode::Type::key;
}

// What is wrong with DEVICE as a source of events, or "". A missing device is fine here: the
// reader opens it when it appears.
std::string check_device(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return "";
  if (S_ISFIFO(st.st_mode)) return "";
  if (!S_ISCHR(st.st_mode)) {
    const char* what = S_ISDIR(st.st_mode)   ? "a directory"
                       : S_ISREG(st.st_mode) ? "a regular file"
                                             : "not a device";
    return path + " is " + what + ", neither an input event device (/dev/input/...) nor a FIFO";
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == EACCES || errno == EPERM) {
      return "cannot open " + path + " (" + std::strerror(errno) +
             "): the daemon's user must be allowed to read it (group input)";
    }
    return "";  // unplugged meanwhile: the reader says so and waits for it
  }
  int version = 0;
  const bool evdev = ::ioctl(fd, EVIOCGVERSION, &version) == 0;
  ::close(fd);
  if (!evdev) return path + " is a character device but no input event device (/dev/input/...)";
  return "";
}

}  // namespace

bool uses_evdev(const config::MachineConfig& config) {
  bool any = false;
  for_each_panel_address(config.panel, [&](const SignalAddress& a) { any |= is_evdev(a); });
  return any;
}

EvdevDriver::EvdevDriver() : notices_(std::make_unique<EvdevNotices>()) {}

EvdevDriver::~EvdevDriver() {
  readers_.clear();
}

std::string EvdevDriver::configure(const config::MachineConfig& machine,
                                   const std::vector<int>& joints) {
  if (!joints.empty()) return "drives no joints: it reads [PANEL] inputs of input devices only";
  if (!readers_.empty()) return "configured twice";
  const config::PanelConfig& panel = machine.panel;
  struct Device {
    std::string key;  // the first key naming it, for messages
    const SignalAddress* address = nullptr;
    std::vector<EvdevBinding> bindings;
  };
  std::map<std::string, Device> devices;
  const auto bind = [&](const std::string& key, const SignalAddress& a, Target target,
                        int index) -> std::string {
    if (!is_evdev(a)) return "";
    const std::optional<EvdevCode> code = config::evdev_code(a.code);
    if (!code) {
      return where(key, a) + "'" + a.code +
             "' is no event code of <linux/input-event-codes.h> (evtest lists a device's codes)";
    }
    if (code->type != type_for(target)) {
      return where(key, a) + a.code + " is " + kind_of(code->type) + "; " + key + " needs " +
             kind_of(type_for(target));
    }
    if (a.device.empty()) return where(key, a) + "no device path";
    Device& device = devices[a.device];
    if (device.address == nullptr) {
      device.key = key;
      device.address = &a;
    }
    device.bindings.push_back(EvdevBinding{code->event_type(), code->code, target, index});
    return "";
  };
  const auto no_quadrature = [&](const std::string& prefix,
                                 const config::PanelCounterWiring& w) -> std::string {
    for (const auto* a : {&w.a, &w.b}) {
      if (is_evdev(*a)) {
        return where(prefix + (a == &w.a ? "_A" : "_B"), *a) +
               "an input device gives no A/B quadrature; wire its REL_ code to " + prefix +
               "_COUNTS";
      }
    }
    return "";
  };
  std::string problem;
  for (int i = 0; i < config::kPanelInputs && problem.empty(); ++i) {
    problem = bind(config::panel_input_key(static_cast<config::PanelInput>(i)),
                   panel.inputs[static_cast<std::size_t>(i)], Target::input, i);
  }
  if (problem.empty()) problem = no_quadrature("MPG", panel.mpg);
  if (problem.empty()) {
    problem = bind("MPG_COUNTS", panel.mpg.counts, Target::counter,
                   static_cast<int>(config::PanelCounter::mpg));
  }
  for (int k = 0; k < config::kPanelAnalogs && problem.empty(); ++k) {
    const config::OverrideKnob& knob = panel.knobs[static_cast<std::size_t>(k)];
    const std::string name = panel_counter_key(k + 1);
    problem = no_quadrature(name, knob.encoder);
    if (problem.empty())
      problem = bind(name + "_COUNTS", knob.encoder.counts, Target::counter, k + 1);
    if (problem.empty()) problem = bind(name + "_ANALOG", knob.analog, Target::analog, k);
  }
  for (int l = 0; l < config::kPanelLights && problem.empty(); ++l) {
    const SignalAddress& a = panel.lights[static_cast<std::size_t>(l)];
    if (is_evdev(a)) {
      problem = where(std::string(config::panel_light_key(static_cast<config::PanelLight>(l))), a) +
                "an input device has no lights to drive";
    }
  }
  if (!problem.empty()) return problem;
  for (const auto& [path, device] : devices) {
    if (std::string bad = check_device(path); !bad.empty())
      return where(device.key, *device.address) + bad;
  }
  const std::int64_t hold_ns = std::int64_t{panel.debounce_ms} * 1'000'000 + kHoldMarginNs;
  for (auto& [path, device] : devices) {
    readers_.push_back(
        std::make_unique<EvdevReader>(path, std::move(device.bindings), hold_ns, *notices_));
  }
  return "";
}

void EvdevDriver::enable() {
  for (auto& reader : readers_)
    reader->start();
}

void EvdevDriver::disable() {
  for (auto& reader : readers_)
    reader->stop();
}

void EvdevDriver::read_io(IoFeedback& feedback) noexcept {
  for (const auto& reader : readers_)
    reader->publish(feedback.panel);
}

bool EvdevDriver::take_notice(DriverNotice& out) {
  return notices_->take(out);
}

std::uint64_t EvdevDriver::losses() const noexcept {
  std::uint64_t total = 0;
  for (const auto& reader : readers_)
    total += reader->losses();
  return total;
}

}  // namespace cncd::drivers
