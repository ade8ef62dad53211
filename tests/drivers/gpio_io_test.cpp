// Signals and the spindle of the GPIO driver, in virtual time through the recording backend:
// coolant and digital outputs, the spindle's enable, direction and PWM lines, the speed ramp,
// the quadrature encoder and the digital inputs.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "cncd/drivers/gpio_driver.hpp"
#include "test_util.hpp"

namespace cncd::test {
namespace {

using drivers::GpioDriver;
using drivers::IoCommand;
using drivers::IoFeedback;
using drivers::JointCommand;
using drivers::JointFeedback;

constexpr std::int64_t kBaseNs = 100'000;  // a 10 kHz base thread
constexpr int kBasePerServo = 10;

config::SignalAddress gpio(const std::string& line) {
  config::SignalAddress a;
  a.kind = config::SignalAddress::Kind::gpio;
  a.active_low = line[0] == '!';
  a.line = a.active_low ? line.substr(1) : line;
  a.text = "gpio:" + line;
  return a;
}

// Duty of a recorded signal between `from_ns` and `to_ns`: time high over the span.
double duty(const std::vector<VcdChange>& changes, const std::string& signal, std::int64_t from_ns,
            std::int64_t to_ns) {
  int level = 0;
  std::int64_t high_ns = 0;
  std::int64_t since = from_ns;
  for (const auto& c : changes) {
    if (c.signal != signal) continue;
    if (c.time_ns <= from_ns) {
      level = c.level;
      continue;
    }
    if (c.time_ns >= to_ns) break;
    if (level == 1) high_ns += c.time_ns - since;
    since = c.time_ns;
    level = c.level;
  }
  if (level == 1) high_ns += to_ns - since;
  return static_cast<double>(high_ns) / static_cast<double>(to_ns - from_ns);
}

class GpioIo : public ::testing::Test {
 protected:
  // One step/dir joint on lines 0 and 1, the spindle and signals as `setup` arranges them.
  template <typename Setup>
  std::string start(Setup setup) {
    const std::string gpio_section =
        "[GPIO]\nCHIP = vcd:" + vcd_path().string() + "\nDEBOUNCE_NS = 300000\n";
    loaded_ = load_machine(dir_, 1,
                           "DRIVER = gpio\nSCALE = 100\nSTEP_LINE = 0\nDIR_LINE = 1\n"
                           "STEPLEN = 100000\nSTEPSPACE = 100000\n",
                           gpio_section, kBaseNs);
    if (!loaded_.ok()) return "config";
    config_ = *loaded_.config;
    config_.spindle.present = true;
    config_.spindle.driver = config::SpindleDriver::gpio;
    config_.spindle.max_forward_velocity = 24000;
    setup(config_);
    driver_.use_manual_clock(true);
    auto problem = driver_.configure(config_, {0});
    if (!problem.empty()) return problem;
    vcd_ = dynamic_cast<drivers::VcdBackend*>(driver_.backend());
    driver_.enable();
    return "";
  }
  void TearDown() override { driver_.disable(); }
  std::filesystem::path vcd_path() const { return dir_.path() / "io.vcd"; }

  // One servo period: joint at `x`, then the outputs, then the base thread's periods.
  IoFeedback servo(double x, const IoCommand& io) {
    JointCommand joint{x, 0, true};
    driver_.write(&joint, 1);
    driver_.write_io(io);
    for (int i = 0; i < kBasePerServo; ++i)
      driver_.run_base_period(now_ns_ += kBaseNs);
    IoFeedback fb;
    driver_.read_io(fb);
    return fb;
  }
  IoFeedback servo_for(int periods, double x, const IoCommand& io) {
    IoFeedback fb;
    for (int i = 0; i < periods; ++i)
      fb = servo(x, io);
    return fb;
  }

  TempDir dir_;
  config::LoadResult loaded_;
  config::MachineConfig config_;
  GpioDriver driver_;
  drivers::VcdBackend* vcd_ = nullptr;
  std::int64_t now_ns_ = 0;
};

IoCommand m3(double rpm) {
  IoCommand c;
  c.spindle = drivers::SpindleCommand{true, false, rpm};
  return c;
}

TEST_F(GpioIo, RecordsCoolantOutputsAndTheSpindleBeforeTheFirstStep) {
  ASSERT_EQ(start([](config::MachineConfig& c) {
              c.io.flood = gpio("5");
              c.io.mist = gpio("!GPIO6");
              c.io.digital_outputs[2] = gpio("7");
              c.spindle.enable = gpio("10");
              c.spindle.direction = gpio("11");
              c.spindle.pwm = gpio("12");
              c.spindle.pwm_frequency = 1000;
            }),
            "");
  IoCommand off;
  servo_for(5, 0, off);  // placed, idle
  IoCommand on = m3(6000);
  on.flood = true;
  on.digital = 1u << 2;
  servo_for(20, 0, on);  // spindle up, coolant on
  double x = 0;
  for (int i = 0; i < 20; ++i)
    servo(x += 0.05, on);  // then the cut
  on.flood = false;
  on.mist = true;
  servo_for(5, x, on);
  servo_for(5, x, off);
  driver_.disable();

  const auto changes = read_vcd(vcd_path());
  std::map<std::string, std::vector<std::pair<std::int64_t, int>>> by_signal;
  for (const auto& c : changes)
    by_signal[c.signal].emplace_back(c.time_ns, c.level);
  for (const char* name : {"spindle_enable", "spindle_dir", "spindle_pwm", "flood", "mist", "dout2",
                           "j0_step", "j0_dir"}) {
    EXPECT_TRUE(by_signal.count(name)) << name;
  }
  const auto first_rise = [&](const std::string& name) -> std::int64_t {
    for (const auto& [t, level] : by_signal[name])
      if (level == 1 && t > 0) return t;
    return -1;
  };
  const std::int64_t spindle_on = first_rise("spindle_enable");
  const std::int64_t first_step = first_rise("j0_step");
  ASSERT_GT(spindle_on, 0);
  ASSERT_GT(first_step, 0);
  EXPECT_LT(spindle_on, first_step);
  EXPECT_NEAR(static_cast<double>(first_step - spindle_on), 20e6, 2e6);  // 20 servo periods
  EXPECT_GT(first_rise("flood"), 0);
  EXPECT_GT(first_rise("dout2"), 0);
  EXPECT_EQ(first_rise("spindle_dir"), -1);  // M3: forward, low
  // Mist is active low: it goes high (off) at once and low when it comes on.
  EXPECT_EQ(by_signal["mist"].back().second, 1);
  // 6000 of 24000 rpm: a quarter duty, once on.
  EXPECT_NEAR(duty(changes, "spindle_pwm", spindle_on + 2'000'000, spindle_on + 22'000'000), 0.25,
              0.01);
  EXPECT_EQ(by_signal["spindle_pwm"].back().second, 0);
  EXPECT_EQ(by_signal["spindle_enable"].back().second, 0);
}

TEST_F(GpioIo, WithoutAnEncoderTheSpeedIsTheRamp) {
  ASSERT_EQ(start([](config::MachineConfig& c) {
              c.spindle.enable = gpio("10");
              c.spindle.direction = gpio("11");
              c.spindle.acceleration = 12000;  // rpm/s: 12 rpm per servo period
            }),
            "");
  IoFeedback fb = servo_for(50, 0, m3(1200));
  EXPECT_TRUE(fb.spindle.present);
  EXPECT_FALSE(fb.spindle.has_position);
  EXPECT_NEAR(fb.spindle.rpm, 600, 1e-6);
  fb = servo_for(60, 0, m3(1200));
  EXPECT_NEAR(fb.spindle.rpm, 1200, 1e-6);
  // M4: through zero (100 ms) and back up; the direction line changes at zero.
  IoCommand m4 = m3(1200);
  m4.spindle.reverse = true;
  fb = servo_for(50, 0, m4);
  EXPECT_NEAR(fb.spindle.rpm, 600, 1e-6);
  fb = servo_for(100, 0, m4);
  EXPECT_NEAR(fb.spindle.rpm, 600, 1e-6);
  EXPECT_FALSE(fb.spindle.stale || fb.spindle.fault);
}

// The base thread's reading answers the spindle command it ran with: a command the base
// thread has not taken yet is not acknowledged.
TEST_F(GpioIo, AReadingAcknowledgesTheCommandTheBaseThreadRanWith) {
  ASSERT_EQ(start([](config::MachineConfig& c) {
              c.spindle.enable = gpio("10");
              c.spindle.direction = gpio("11");
              c.spindle.acceleration = 12000;
            }),
            "");
  IoCommand c = m3(1200);
  c.spindle.sequence = 3;
  IoFeedback fb = servo_for(2, 0, c);
  EXPECT_EQ(fb.spindle.acknowledged, 3u);
  // Written, but no base period has run since: the reading is the old command's.
  c.spindle.sequence = 4;
  c.spindle.reverse = true;
  driver_.write_io(c);
  fb = IoFeedback{};
  driver_.read_io(fb);
  EXPECT_EQ(fb.spindle.acknowledged, 3u);
  fb = servo(0, c);
  EXPECT_EQ(fb.spindle.acknowledged, 4u);
}

TEST_F(GpioIo, AQuadratureEncoderGivesSpeedAndPosition) {
  ASSERT_EQ(start([](config::MachineConfig& c) {
              c.spindle.enable = gpio("10");
              c.spindle.encoder_a = gpio("20");
              c.spindle.encoder_b = gpio("21");
              c.spindle.encoder_index = gpio("22");
              c.spindle.encoder_ppr = 100;
            }),
            "");
  ASSERT_NE(vcd_, nullptr);
  // A spindle at `rpm` (signed): 400 counts per revolution, fed to the lines every base period.
  double counts = 0;
  const auto turn = [&](double rpm, int servo_periods) {
    IoFeedback fb;
    for (int p = 0; p < servo_periods; ++p) {
      driver_.write_io(m3(std::abs(rpm)));
      for (int i = 0; i < kBasePerServo; ++i) {
        counts += rpm / 60.0 * 400 * 1e-4;
        const auto whole = static_cast<long long>(std::floor(counts));
        const int phase = static_cast<int>(((whole % 4) + 4) % 4);  // 00 10 11 01
        vcd_->set_input_level(20, phase == 1 || phase == 2);
        vcd_->set_input_level(21, phase == 2 || phase == 3);
        vcd_->set_input_level(22, ((whole % 400) + 400) % 400 == 0);
        driver_.run_base_period(now_ns_ += kBaseNs);
      }
      fb = IoFeedback{};
      driver_.read_io(fb);
    }
    return fb;
  };
  IoFeedback fb = turn(600, 1000);  // 10 rev/s for 1 s
  EXPECT_TRUE(fb.spindle.has_position);
  EXPECT_NEAR(fb.spindle.rpm, 600, 20);
  EXPECT_NEAR(fb.spindle.revolutions, 10, 0.01);
  fb = turn(-300, 1000);  // back 5 revolutions
  EXPECT_NEAR(fb.spindle.rpm, 300, 20);
  EXPECT_NEAR(fb.spindle.revolutions, 5, 0.01);
  fb = turn(0, 50);
  EXPECT_NEAR(fb.spindle.rpm, 0, 1e-9);
}

TEST_F(GpioIo, DigitalInputsAreDebouncedAndMayBeActiveLow) {
  ASSERT_EQ(start([](config::MachineConfig& c) {
              c.spindle.present = false;
              c.io.digital_inputs[3] = gpio("30");
              c.io.digital_inputs[31] = gpio("!31");
            }),
            "");
  vcd_->set_input_level(31, true);  // the active-low input is off
  IoFeedback fb = servo_for(2, 0, IoCommand{});
  EXPECT_EQ(fb.digital, 0u);
  EXPECT_FALSE(fb.spindle.present);
  vcd_->set_input_level(30, true);
  vcd_->set_input_level(31, false);
  driver_.run_base_period(now_ns_ += kBaseNs);  // 100 us: shorter than the 300 us debounce
  fb = IoFeedback{};
  driver_.read_io(fb);
  EXPECT_EQ(fb.digital, 0u);
  fb = servo_for(1, 0, IoCommand{});
  EXPECT_EQ(fb.digital, (1u << 3) | (1u << 31));
}

TEST_F(GpioIo, ConfigurationProblemsNameTheAddress) {
  EXPECT_NE(start([](config::MachineConfig& c) {
              c.io.analog_outputs[0] = gpio("9");
            }).find("gpio:9: a GPIO line carries no analog value"),
            std::string::npos);
}

TEST_F(GpioIo, ALineServesOneSignal) {
  EXPECT_NE(start([](config::MachineConfig& c) {
              c.io.flood = gpio("1");
            }).find("gpio:1: line 1 is already used"),
            std::string::npos);
}

TEST_F(GpioIo, PwmMustBeSlowerThanHalfTheBaseRate) {
  EXPECT_NE(start([](config::MachineConfig& c) {
              c.spindle.pwm = gpio("12");
              c.spindle.pwm_frequency = 6000;
            }).find("PWM_FREQUENCY"),
            std::string::npos);
}

}  // namespace
}  // namespace cncd::test
