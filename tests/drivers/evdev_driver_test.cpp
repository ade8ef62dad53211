// The evdev driver on a real FIFO: recorded `struct input_event` records written as a USB
// pendant's event device would deliver them, read back through read_io() as the servo thread
// does.
#include <fcntl.h>
#include <linux/input.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/config/evdev_codes.hpp"
#include "cncd/drivers/evdev_driver.hpp"

namespace cncd::drivers {
namespace {

using config::PanelAnalog;
using config::PanelCounter;
using config::PanelInput;
using namespace std::chrono_literals;

// Generous: the outcome, not the time, is what these tests judge.
constexpr auto kPatience = 10s;

class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "cncd-evdev-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

config::SignalAddress evdev(const std::string& device, const std::string& code) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::evdev;
  a.device = device;
  a.code = code;
  a.text = "evdev:" + device + ":" + code;
  a.source = {"pendant.ini", 12};
  return a;
}

std::uint64_t bit(PanelInput input) {
  return std::uint64_t{1} << static_cast<int>(input);
}

constexpr auto kMpg = static_cast<std::size_t>(PanelCounter::mpg);
constexpr auto kFeedKnob = static_cast<std::size_t>(PanelAnalog::feed_override);

// A ShuttleXpress-like pendant: F1 is cycle start, BTN_4 feed hold, the jog dial the MPG and
// an absolute axis the feed override knob.
config::MachineConfig pendant_config(const std::string& device, int debounce_ms = 10) {
  config::MachineConfig c;
  c.panel.present = true;
  c.panel.debounce_ms = debounce_ms;
  c.panel.inputs[static_cast<std::size_t>(PanelInput::cycle_start)] = evdev(device, "KEY_F1");
  c.panel.inputs[static_cast<std::size_t>(PanelInput::feed_hold)] = evdev(device, "BTN_4");
  c.panel.mpg.counts = evdev(device, "REL_DIAL");
  c.panel.knobs[kFeedKnob].analog = evdev(device, "ABS_X");
  return c;
}

std::string record(std::uint16_t type, std::uint16_t code, std::int32_t value) {
  input_event event{};
  event.type = type;
  event.code = code;
  event.value = value;
  return std::string(reinterpret_cast<const char*>(&event), sizeof event);
}

std::string key(std::uint16_t code, std::int32_t value) {
  return record(EV_KEY, code, value) + record(EV_SYN, SYN_REPORT, 0);
}

std::string dial(std::int32_t value) {
  return record(EV_REL, REL_DIAL, value) + record(EV_SYN, SYN_REPORT, 0);
}

// The writing end of the FIFO, as the program that feeds a pendant's events would hold it.
class Writer {
 public:
  explicit Writer(const std::filesystem::path& fifo) {
    // A FIFO's writer cannot open it before its reader has (ENXIO): wait for the driver.
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while ((fd_ = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC)) < 0 &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(5ms);
    }
    if (fd_ >= 0) ::fcntl(fd_, F_SETFL, 0);
  }
  ~Writer() { close(); }
  bool open() const { return fd_ >= 0; }
  bool write(const std::string& bytes) const {
    return fd_ >= 0 &&
           ::write(fd_, bytes.data(), bytes.size()) == static_cast<ssize_t>(bytes.size());
  }
  void close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

class EvdevDriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::signal(SIGPIPE, SIG_IGN);
    fifo_ = dir_.path() / "pendant";
  }

  std::string configure(const config::MachineConfig& c) { return driver_.configure(c, {}); }

  void make_fifo() { ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0) << std::strerror(errno); }

  PanelFeedback read() {
    IoFeedback feedback;
    driver_.read_io(feedback);
    return feedback.panel;
  }

  // Reads the panel as the servo thread would until `done` holds; false if it never does.
  bool wait_for(const std::function<bool(const PanelFeedback&)>& done) {
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (std::chrono::steady_clock::now() < deadline) {
      if (done(read())) return true;
      std::this_thread::sleep_for(1ms);
    }
    return false;
  }

  bool wait_losses(std::uint64_t count) {
    return wait_for([&](const PanelFeedback&) { return driver_.losses() >= count; });
  }

  // Takes notices until one holds `text`; false if none does.
  bool wait_notice(const std::string& text, DriverNotice::Level level) {
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (std::chrono::steady_clock::now() < deadline) {
      DriverNotice notice;
      while (driver_.take_notice(notice)) {
        notices_.push_back(notice.text);
        if (notice.text.find(text) != std::string::npos && notice.level == level) return true;
      }
      std::this_thread::sleep_for(1ms);
    }
    return false;
  }

  TempDir dir_;
  std::filesystem::path fifo_;
  EvdevDriver driver_;
  std::vector<std::string> notices_;
};

TEST(EvdevCodes, NamesComeFromTheKernelHeader) {
  const auto f1 = config::evdev_code("KEY_F1");
  ASSERT_TRUE(f1);
  EXPECT_EQ(f1->type, config::EvdevCode::Type::key);
  EXPECT_EQ(f1->code, KEY_F1);
  EXPECT_EQ(f1->event_type(), EV_KEY);
  EXPECT_EQ(config::evdev_code("BTN_4")->code, BTN_4);
  EXPECT_EQ(config::evdev_code("KEY_KP5")->code, KEY_KP5);
  const auto dial = config::evdev_code("REL_DIAL");
  ASSERT_TRUE(dial);
  EXPECT_EQ(dial->event_type(), EV_REL);
  EXPECT_EQ(dial->code, REL_DIAL);
  EXPECT_EQ(config::evdev_code("ABS_RZ")->event_type(), EV_ABS);
  for (const char* bad : {"KEY_MAX", "KEY_CNT", "REL_RESERVED", "key_f1", "KEY_F99", "EV_KEY", ""})
    EXPECT_FALSE(config::evdev_code(bad)) << bad;
}

TEST(EvdevDialStep, ShuttlePositionsBecomeSteps) {
  int last = -1;
  EXPECT_EQ(evdev_dial_step(last, 17), 0);  // the counter's start is unknown: no step
  EXPECT_EQ(evdev_dial_step(last, 18), 1);
  EXPECT_EQ(evdev_dial_step(last, 20), 2);
  EXPECT_EQ(evdev_dial_step(last, 19), -1);
  last = 254;
  EXPECT_EQ(evdev_dial_step(last, 255), 1);
  EXPECT_EQ(evdev_dial_step(last, 1), 2);  // 0 never comes: its step arrives with 1
  EXPECT_EQ(evdev_dial_step(last, 255), -2);
  EXPECT_EQ(last, 255);
}

TEST_F(EvdevDriverTest, ButtonsDialAndKnobReachReadIo) {
  make_fifo();
  ASSERT_EQ(configure(pendant_config(fifo_.string())), "");
  driver_.enable();
  Writer writer(fifo_);
  ASSERT_TRUE(writer.open());
  ASSERT_TRUE(wait_notice("reading (a FIFO)", DriverNotice::Level::info));

  ASSERT_TRUE(writer.write(key(KEY_F1, 1)));
  EXPECT_TRUE(
      wait_for([](const PanelFeedback& p) { return p.inputs & bit(PanelInput::cycle_start); }));
  ASSERT_TRUE(writer.write(dial(+5) + dial(-2) + record(EV_ABS, ABS_X, 512) +
                           record(EV_SYN, SYN_REPORT, 0)));
  EXPECT_TRUE(wait_for(
      [](const PanelFeedback& p) { return p.counts[kMpg] == 3 && p.analog[kFeedKnob] == 512; }));
  ASSERT_TRUE(writer.write(key(KEY_F1, 2) + key(KEY_F1, 0) + dial(-4)));  // repeat, release
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) {
    return (p.inputs & bit(PanelInput::cycle_start)) == 0 && p.counts[kMpg] == 0xffffffffu;
  }));

  // Only the evdev signals are the driver's: what another driver reported stays.
  IoFeedback feedback;
  feedback.panel.inputs = bit(PanelInput::stop) | bit(PanelInput::cycle_start);
  feedback.panel.counts[1] = 77;
  driver_.read_io(feedback);
  EXPECT_EQ(feedback.panel.inputs, bit(PanelInput::stop));
  EXPECT_EQ(feedback.panel.counter_bits[kMpg], 32);
  EXPECT_EQ(feedback.panel.counter_bits[1], 0);
  EXPECT_EQ(feedback.panel.counts[1], 77u);
  driver_.disable();
}

TEST_F(EvdevDriverTest, PressAndReleaseInOneWriteIsStillSeen) {
  make_fifo();
  // The press shows at least DEBOUNCE_MS: long enough here for any poll of this test to see it.
  ASSERT_EQ(configure(pendant_config(fifo_.string(), 1000)), "");
  driver_.enable();
  Writer writer(fifo_);
  ASSERT_TRUE(writer.write(key(BTN_4, 1) + key(BTN_4, 0)));
  EXPECT_TRUE(
      wait_for([](const PanelFeedback& p) { return p.inputs & bit(PanelInput::feed_hold); }));
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) { return p.inputs == 0; }));
}

TEST_F(EvdevDriverTest, StopPressedAsTheDeviceIsLostIsStillSeen) {
  make_fifo();
  config::MachineConfig c = pendant_config(fifo_.string(), 1000);
  c.panel.inputs[static_cast<std::size_t>(PanelInput::stop)] = evdev(fifo_.string(), "KEY_ESC");
  ASSERT_EQ(configure(c), "");
  driver_.enable();
  {
    Writer writer(fifo_);
    ASSERT_TRUE(writer.write(key(KEY_ESC, 1)));
  }  // and the cable comes out
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) { return p.inputs == bit(PanelInput::stop); }));
  EXPECT_TRUE(wait_losses(1));
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) { return p.inputs == 0; }));
}

TEST_F(EvdevDriverTest, WriterClosingReleasesButtonsAndReconnects) {
  make_fifo();
  ASSERT_EQ(configure(pendant_config(fifo_.string())), "");
  driver_.enable();
  auto writer = std::make_unique<Writer>(fifo_);
  ASSERT_TRUE(writer->write(key(KEY_F1, 1) + dial(4)));
  ASSERT_TRUE(wait_for([](const PanelFeedback& p) {
    return (p.inputs & bit(PanelInput::cycle_start)) && p.counts[kMpg] == 4;
  }));

  writer.reset();  // the pendant is unplugged with F1 held
  ASSERT_TRUE(wait_losses(1));
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) { return p.inputs == 0; }));
  EXPECT_TRUE(wait_notice("lost (its writer closed it)", DriverNotice::Level::warning));

  writer = std::make_unique<Writer>(fifo_);
  ASSERT_TRUE(writer->open());
  ASSERT_TRUE(writer->write(dial(5) + key(BTN_4, 1)));
  // The counter goes on from where it stood: the servo thread sees 5 counts, not a jump.
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) {
    return p.counts[kMpg] == 9 && p.inputs == bit(PanelInput::feed_hold);
  }));
  EXPECT_EQ(driver_.losses(), 1u);
}

TEST_F(EvdevDriverTest, RecordSplitAcrossWritesIsJoined) {
  make_fifo();
  ASSERT_EQ(configure(pendant_config(fifo_.string())), "");
  driver_.enable();
  Writer writer(fifo_);
  const std::string bytes = dial(7) + key(KEY_F1, 1);
  const std::size_t cut = sizeof(input_event) + 10;  // inside the SYN after the dial
  ASSERT_TRUE(writer.write(bytes.substr(0, cut)));
  ASSERT_TRUE(wait_for([](const PanelFeedback& p) { return p.counts[kMpg] == 7; }));
  std::this_thread::sleep_for(50ms);  // let the reader take the partial record alone
  EXPECT_EQ(read().inputs, 0u);
  ASSERT_TRUE(writer.write(bytes.substr(cut)));
  EXPECT_TRUE(
      wait_for([](const PanelFeedback& p) { return p.inputs & bit(PanelInput::cycle_start); }));
  EXPECT_EQ(read().counts[kMpg], 7u);
  EXPECT_EQ(driver_.losses(), 0u);
}

TEST_F(EvdevDriverTest, GarbageIsDroppedAndTheNextStreamReadsWhole) {
  make_fifo();
  ASSERT_EQ(configure(pendant_config(fifo_.string())), "");
  driver_.enable();
  {
    Writer writer(fifo_);
    // Whole records of types and codes nobody asked for change nothing.
    ASSERT_TRUE(writer.write(record(0x1f, 3, 9) + key(KEY_A, 1) + record(EV_REL, REL_X, 50) +
                             record(EV_ABS, ABS_Y, 50) + dial(2)));
    ASSERT_TRUE(wait_for([](const PanelFeedback& p) { return p.counts[kMpg] == 2; }));
    EXPECT_EQ(read().inputs, 0u);
    EXPECT_EQ(read().analog[kFeedKnob], 0);
    ASSERT_TRUE(writer.write("0123456789"));  // ten bytes: not a whole record
  }
  ASSERT_TRUE(wait_losses(1));
  EXPECT_TRUE(wait_notice("10 bytes of an incomplete event dropped", DriverNotice::Level::warning));
  Writer writer(fifo_);
  ASSERT_TRUE(writer.write(key(KEY_F1, 1) + dial(1)));
  EXPECT_TRUE(wait_for([](const PanelFeedback& p) {
    return p.inputs == bit(PanelInput::cycle_start) && p.counts[kMpg] == 3;
  }));
}

TEST_F(EvdevDriverTest, MissingDeviceIsReadOnceItAppears) {
  ASSERT_EQ(configure(pendant_config(fifo_.string())), "");
  driver_.enable();
  EXPECT_TRUE(
      wait_notice("cannot be opened (No such file or directory)", DriverNotice::Level::warning));
  make_fifo();
  Writer writer(fifo_);
  ASSERT_TRUE(writer.open());
  ASSERT_TRUE(writer.write(key(BTN_4, 1)));
  EXPECT_TRUE(
      wait_for([](const PanelFeedback& p) { return p.inputs == bit(PanelInput::feed_hold); }));
}

TEST_F(EvdevDriverTest, DisableWithoutAWriterReturns) {
  make_fifo();
  ASSERT_EQ(configure(pendant_config(fifo_.string())), "");
  driver_.enable();
  ASSERT_TRUE(wait_notice("reading (a FIFO)", DriverNotice::Level::info));
  driver_.disable();  // the reader waits in poll() on a FIFO nobody writes: it must still end
  EXPECT_EQ(read().inputs, 0u);
  driver_.enable();
  Writer writer(fifo_);
  ASSERT_TRUE(writer.write(key(KEY_F1, 1)));
  EXPECT_TRUE(
      wait_for([](const PanelFeedback& p) { return p.inputs == bit(PanelInput::cycle_start); }));
}

TEST_F(EvdevDriverTest, DeviceThatIsNoDeviceIsRefused) {
  const std::string file = (dir_.path() / "events.bin").string();
  std::FILE* f = std::fopen(file.c_str(), "w");
  ASSERT_NE(f, nullptr);
  std::fclose(f);
  std::string error = configure(pendant_config(file));
  EXPECT_NE(error.find("pendant.ini:12: [PANEL] CYCLE_START = evdev:" + file + ":KEY_F1"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find(file + " is a regular file"), std::string::npos) << error;

  EvdevDriver other;
  error = other.configure(pendant_config(dir_.path().string()), {});
  EXPECT_NE(error.find(dir_.path().string() + " is a directory"), std::string::npos) << error;

  EvdevDriver null_device;
  error = null_device.configure(pendant_config("/dev/null"), {});
  EXPECT_NE(error.find("/dev/null is a character device but no input event device"),
            std::string::npos)
      << error;
}

TEST_F(EvdevDriverTest, CodesThatDoNotFitTheirKeyAreRefused) {
  const std::string device = fifo_.string();
  const auto refused = [&](config::MachineConfig c, const std::string& expected) {
    EvdevDriver driver;
    const std::string error = driver.configure(c, {});
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  };
  config::MachineConfig c = pendant_config(device);
  c.panel.mpg.counts = evdev(device, "KEY_F2");
  refused(c, "[PANEL] MPG_COUNTS = evdev:" + device +
                 ":KEY_F2: KEY_F2 is a button (KEY_, BTN_); MPG_COUNTS needs a relative axis");
  c = pendant_config(device);
  c.panel.inputs[static_cast<std::size_t>(PanelInput::stop)] = evdev(device, "KEY_STOPP");
  refused(c, "[PANEL] STOP = evdev:" + device + ":KEY_STOPP: 'KEY_STOPP' is no event code");
  c = pendant_config(device);
  c.panel.knobs[kFeedKnob].analog = evdev(device, "REL_WHEEL");
  refused(c, "FEED_OVERRIDE_ANALOG needs an absolute axis (ABS_)");
  c = pendant_config(device);
  c.panel.mpg.counts = {};
  c.panel.mpg.a = evdev(device, "KEY_1");
  refused(c, "[PANEL] MPG_A = evdev:" + device + ":KEY_1: an input device gives no A/B quadrature");
  c = pendant_config(device);
  c.panel.lights[0] = evdev(device, "KEY_1");
  refused(c, "[PANEL] LIGHT_RED = evdev:");
  EvdevDriver driver;
  EXPECT_NE(driver.configure(pendant_config(device), {0}).find("drives no joints"),
            std::string::npos);
}

TEST_F(EvdevDriverTest, MakeDriversMakesOneEvdevDriverForAllDevices) {
  make_fifo();
  config::MachineConfig c = pendant_config(fifo_.string());
  c.panel.inputs[static_cast<std::size_t>(PanelInput::stop)] =
      evdev((dir_.path() / "keypad").string(), "KEY_KPENTER");
  EXPECT_TRUE(uses_evdev(c));
  EXPECT_FALSE(uses_evdev(config::MachineConfig{}));
  std::string error;
  const auto drivers = make_drivers(c, error);
  ASSERT_EQ(error, "");
  ASSERT_EQ(drivers.size(), 1u);
  EXPECT_STREQ(drivers[0].driver->name(), "evdev");
  EXPECT_TRUE(drivers[0].joints.empty());
}

}  // namespace
}  // namespace cncd::drivers
