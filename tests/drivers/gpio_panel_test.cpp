// The panel's `gpio:` signals: buttons and switches on lines (active low with '!'), lights,
// and the MPG's A/B quadrature decoded in the base thread, fed through the recording backend
// and counted exactly; the recording shows the panel's lines and the steps on one time axis.
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "cncd/drivers/gpio_driver.hpp"
#include "test_util.hpp"

namespace cncd::test {
namespace {

using config::PanelCounter;
using config::PanelInput;
using config::PanelLight;
using drivers::GpioDriver;
using drivers::IoCommand;
using drivers::IoFeedback;
using drivers::VcdBackend;

constexpr std::int64_t kBaseNs = 100'000;  // a 10 kHz base thread
constexpr int kBasePerServo = 10;
constexpr int kLineA = 32;
constexpr int kLineB = 33;

config::SignalAddress gpio(const std::string& line) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::gpio;
  a.active_low = line[0] == '!';
  a.line = a.active_low ? line.substr(1) : line;
  a.text = "gpio:" + line;
  return a;
}

constexpr std::uint64_t bit(PanelInput which) {
  return std::uint64_t{1} << static_cast<int>(which);
}

// The steps that turn an encoder on lines A and B by `counts` (negative: backwards) from
// `phase` (0 .. 3 of 00 10 11 01, updated), each held `hold` base periods.
std::vector<VcdBackend::InputStep> quadrature(int counts, int& phase, std::uint32_t hold) {
  std::vector<VcdBackend::InputStep> steps;
  for (int i = 0; i < std::abs(counts); ++i) {
    const int next = (phase + (counts > 0 ? 1 : 3)) % 4;
    const bool a = next == 1 || next == 2;
    const bool b = next == 2 || next == 3;
    const bool a_was = phase == 1 || phase == 2;
    steps.push_back(a != a_was ? VcdBackend::InputStep{kLineA, a, hold}
                               : VcdBackend::InputStep{kLineB, b, hold});
    phase = next;
  }
  return steps;
}

class GpioPanel : public ::testing::Test {
 protected:
  // One step/dir joint (1000 steps/mm) on lines 0 and 1, the panel as `setup` wires it.
  template <typename Setup>
  std::string start(Setup setup, bool manual_clock = true) {
    loaded_ = load_machine(dir_, 1, "DRIVER = gpio\nSCALE = 1000\nSTEP_LINE = 0\nDIR_LINE = 1\n",
                           "[GPIO]\nCHIP = vcd:" + vcd_path().string() + "\n", kBaseNs);
    if (!loaded_.ok()) return "config";
    config_ = *loaded_.config;
    config_.panel.present = true;
    setup(config_.panel);
    driver_.use_manual_clock(manual_clock);
    auto problem = driver_.configure(config_, {0});
    if (!problem.empty()) return problem;
    vcd_ = dynamic_cast<VcdBackend*>(driver_.backend());
    driver_.enable();
    return "";
  }
  void TearDown() override { driver_.disable(); }
  std::filesystem::path vcd_path() const { return dir_.path() / "panel.vcd"; }

  // One servo period in virtual time: joint at `x`, the lights, then the base periods.
  drivers::PanelFeedback servo(double x, std::uint32_t lights = 0) {
    drivers::JointCommand joint{x, 0, true};
    driver_.write(&joint, 1);
    IoCommand io;
    io.panel = lights;
    driver_.write_io(io);
    for (int i = 0; i < kBasePerServo; ++i)
      driver_.run_base_period(now_ns_ += kBaseNs);
    IoFeedback fb;
    driver_.read_io(fb);
    return fb.panel;
  }
  drivers::PanelFeedback read_panel() {
    IoFeedback fb;
    driver_.read_io(fb);
    return fb.panel;
  }
  // Real time: waits until the base thread has applied every step fed and run two periods
  // more; false after 20 s.
  bool settle(std::uint64_t fed) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (vcd_->inputs_fed() < fed) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const std::uint64_t periods = driver_.base_stats().periods;
    while (driver_.base_stats().periods < periods + 2) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }

  TempDir dir_;
  config::LoadResult loaded_;
  config::MachineConfig config_;
  GpioDriver driver_;
  VcdBackend* vcd_ = nullptr;
  std::int64_t now_ns_ = 0;
};

// Buttons are read as sampled, each base period: the servo thread debounces them.
TEST_F(GpioPanel, ButtonsAndSwitchesAreReadActiveLowApplied) {
  ASSERT_EQ(start([](config::PanelConfig& p) {
              p.inputs[static_cast<std::size_t>(PanelInput::cycle_start)] = gpio("30");
              p.inputs[static_cast<std::size_t>(PanelInput::door)] = gpio("!GPIO31");
            }),
            "");
  vcd_->set_input_level(31, true);  // door switch closed: the door is shut
  EXPECT_EQ(servo(0).inputs, 0u);
  vcd_->set_input_level(30, true);
  driver_.run_base_period(now_ns_ += kBaseNs);
  EXPECT_EQ(read_panel().inputs, bit(PanelInput::cycle_start)) << "one base period is enough";
  vcd_->set_input_level(30, false);
  vcd_->set_input_level(31, false);  // the door opens
  EXPECT_EQ(servo(0).inputs, bit(PanelInput::door));
  EXPECT_EQ(servo(0).counter_bits[0], 0) << "no encoder wired";
}

TEST_F(GpioPanel, LightsDriveTheirLines) {
  ASSERT_EQ(start([](config::PanelConfig& p) {
              p.lights[static_cast<std::size_t>(PanelLight::red)] = gpio("40");
              p.lights[static_cast<std::size_t>(PanelLight::green)] = gpio("!41");
            }),
            "");
  servo(0);
  servo(0, 1u << static_cast<int>(PanelLight::green));
  servo(0, 1u << static_cast<int>(PanelLight::red));
  driver_.disable();
  std::vector<std::pair<std::string, int>> seen;
  for (const auto& c : read_vcd(vcd_path())) {
    if (c.signal.starts_with("light_")) seen.emplace_back(c.signal, c.level);
  }
  // Initial values, green off (its line high), green lit (low), then red lit and green off.
  const std::vector<std::pair<std::string, int>> expected = {
      {"light_red", 0},   {"light_green", 0}, {"light_green", 1},
      {"light_green", 0}, {"light_red", 1},   {"light_green", 1}};
  EXPECT_EQ(seen, expected);
}

TEST_F(GpioPanel, TheBaseThreadCountsTheMpgExactly) {
  ASSERT_EQ(start(
                [](config::PanelConfig& p) {
                  p.mpg.a = gpio(std::to_string(kLineA));
                  p.mpg.b = gpio("GPIO" + std::to_string(kLineB));
                },
                false),
            "");
  ASSERT_TRUE(settle(0));  // the decoder has seen the lines at rest
  int phase = 0;
  ASSERT_TRUE(vcd_->feed_inputs(quadrature(400, phase, 1)));
  ASSERT_TRUE(settle(400));
  drivers::PanelFeedback p = read_panel();
  EXPECT_EQ(p.counts[0], 400u);
  EXPECT_EQ(p.counter_bits[0], 32);
  // Back past zero: the count wraps at 32 bits.
  ASSERT_TRUE(vcd_->feed_inputs(quadrature(-403, phase, 2)));
  ASSERT_TRUE(settle(803));
  EXPECT_EQ(read_panel().counts[0], 0xfffffffdu);
  EXPECT_EQ(driver_.quadrature_errors(PanelCounter::mpg), 0u);
}

TEST_F(GpioPanel, BothLinesChangingInOneBasePeriodIsAnError) {
  ASSERT_EQ(start([](config::PanelConfig& p) {
              p.mpg.a = gpio(std::to_string(kLineA));
              p.mpg.b = gpio(std::to_string(kLineB));
            }),
            "");
  servo(0);
  ASSERT_TRUE(vcd_->feed_inputs({{kLineA, true, 0}, {kLineB, true, 1}}));  // 00 -> 11
  EXPECT_EQ(servo(0).counts[0], 0u);
  EXPECT_EQ(driver_.quadrature_errors(PanelCounter::mpg), 1u);
  int phase = 2;
  ASSERT_TRUE(vcd_->feed_inputs(quadrature(3, phase, 1)));
  EXPECT_EQ(servo(0).counts[0], 3u);
}

// The MPG as the servo thread would use it: 400 counts, 100 counts a detent, 0.01 mm a detent,
// move the joint 0.04 mm: 40 steps. The recording shows the MPG's lines and enable button,
// then the steps, on one time axis.
TEST_F(GpioPanel, TheRecordingShowsTheWheelAndTheStepsItCaused) {
  ASSERT_EQ(start([](config::PanelConfig& p) {
              p.inputs[static_cast<std::size_t>(PanelInput::mpg_enable)] = gpio("34");
              p.mpg.a = gpio(std::to_string(kLineA));
              p.mpg.b = gpio(std::to_string(kLineB));
            }),
            "");
  servo(0);
  int phase = 0;
  std::vector<VcdBackend::InputStep> steps = {{34, true, 5}};
  for (const auto& s : quadrature(400, phase, 2))
    steps.push_back(s);
  ASSERT_TRUE(vcd_->feed_inputs(steps));
  std::uint32_t first = 0;
  bool enabled = false;
  for (int i = 0; i < 200; ++i) {
    const auto p = read_panel();
    if (!enabled && (p.inputs & bit(PanelInput::mpg_enable)) != 0) {
      enabled = true;
      first = p.counts[0];
    }
    const double detents = enabled ? static_cast<double>(p.counts[0] - first) / 100 : 0;
    servo(detents * 0.01);
  }
  EXPECT_EQ(vcd_->inputs_fed(), steps.size());
  driver_.disable();
  const auto changes = read_vcd(vcd_path());
  EXPECT_EQ(step_stats(changes, 0).net_steps, 40);
  std::int64_t enable_ns = -1, first_a_ns = -1, first_step_ns = -1;
  for (const auto& c : changes) {
    if (c.level != 1) continue;
    if (c.signal == "mpg_enable" && enable_ns < 0) enable_ns = c.time_ns;
    if (c.signal == "mpg_a" && first_a_ns < 0) first_a_ns = c.time_ns;
    if (c.signal == "j0_step" && first_step_ns < 0) first_step_ns = c.time_ns;
  }
  ASSERT_GE(enable_ns, 0);
  EXPECT_LT(enable_ns, first_a_ns);
  EXPECT_LT(first_a_ns, first_step_ns);
}

TEST_F(GpioPanel, CountsAndAnalogKnobsAreRefusedOnLines) {
  EXPECT_NE(start([](config::PanelConfig& p) {
              p.mpg.counts = gpio("5");
            }).find("a GPIO line carries no count: wire the encoder to MPG_A and MPG_B"),
            std::string::npos);
}

TEST_F(GpioPanel, AnEncoderNeedsBothLines) {
  const std::string error = start([](config::PanelConfig& p) { p.knobs[2].encoder.a = gpio("5"); });
  EXPECT_NE(error.find("SPINDLE_OVERRIDE_A and SPINDLE_OVERRIDE_B"), std::string::npos) << error;
}

TEST_F(GpioPanel, APanelLineUsedTwiceIsRefused) {
  const std::string error = start([](config::PanelConfig& p) {
    p.inputs[0] = gpio("7");
    p.lights[0] = gpio("7");
  });
  EXPECT_NE(error.find("line 7 is already used"), std::string::npos) << error;
}

}  // namespace
}  // namespace cncd::test
