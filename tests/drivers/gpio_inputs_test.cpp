// Switch inputs of the step/dir driver: levels injected through the recording backend, read
// back through the driver interface with active-low handling and debounce.
#include <gtest/gtest.h>

#include "cncd/config/ini_file.hpp"
#include "cncd/drivers/gpio_driver.hpp"
#include "test_util.hpp"

namespace cncd::test {
namespace {

using drivers::GpioDriver;
using drivers::JointFeedback;
using drivers::MachineInputs;

constexpr std::int64_t kBaseNs = 10'000;

class GpioInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string joint =
        "DRIVER = gpio\nSCALE = 100\nSTEP_LINE = GPIO{j}0\nDIR_LINE = GPIO{j}1\n"
        "HOME_SWITCH_LINE = GPIO{j}2\nMIN_LIMIT_LINE = GPIO{j}3\nMIN_LIMIT_ACTIVE_LOW = 1\n"
        "MAX_LIMIT_LINE = {j}4\n";
    const std::string gpio = "[GPIO]\nCHIP = vcd:" + (dir_.path() / "in.vcd").string() +
                             "\nESTOP_LINE = 40\nESTOP_ACTIVE_LOW = YES\nPROBE_LINE = GPIO41\n"
                             "DEBOUNCE_NS = 50000\n";
    loaded_ = load_machine(dir_, 2, joint, gpio, kBaseNs);
    ASSERT_TRUE(loaded_.ok());
    driver_.use_manual_clock(true);
    ASSERT_EQ(driver_.configure(*loaded_.config, {0, 1}), "");
    vcd_ = dynamic_cast<drivers::VcdBackend*>(driver_.backend());
    ASSERT_NE(vcd_, nullptr);
    driver_.enable();
    // Healthy machine: estop loop closed (high), minimum limits closed (high, active low).
    vcd_->set_input_level(40, true);
    vcd_->set_input_level(3, true);
    vcd_->set_input_level(13, true);
    periods(10);
  }
  void TearDown() override { driver_.disable(); }

  void periods(int n) {
    for (int i = 0; i < n; ++i)
      driver_.run_base_period(now_ns_ += kBaseNs);
  }
  JointFeedback feedback(int joint) {
    JointFeedback fb[2];
    driver_.read(fb, 2);
    return fb[joint];
  }
  MachineInputs inputs() {
    MachineInputs in;
    driver_.read_inputs(in);
    return in;
  }

  TempDir dir_;
  config::LoadResult loaded_;
  GpioDriver driver_;
  drivers::VcdBackend* vcd_ = nullptr;
  std::int64_t now_ns_ = 0;
};

TEST_F(GpioInputs, HealthyMachineReadsNoSwitches) {
  for (int j = 0; j < 2; ++j) {
    const auto fb = feedback(j);
    EXPECT_FALSE(fb.home_switch || fb.min_limit || fb.max_limit) << "joint " << j;
  }
  EXPECT_FALSE(inputs().estop);
  EXPECT_FALSE(inputs().probe);
  const auto caps = driver_.capabilities();
  EXPECT_TRUE(caps & drivers::kCapHomeSwitch);
  EXPECT_TRUE(caps & drivers::kCapLimitSwitches);
  EXPECT_TRUE(caps & drivers::kCapEstopInput);
}

TEST_F(GpioInputs, ActiveHighSwitchesAfterDebounce) {
  vcd_->set_input_level(12, true);  // joint 1 home
  vcd_->set_input_level(4, true);   // joint 0 max limit
  periods(4);
  EXPECT_FALSE(feedback(1).home_switch) << "must hold for 5 base periods";
  periods(1);
  EXPECT_TRUE(feedback(1).home_switch);
  EXPECT_TRUE(feedback(0).max_limit);
  EXPECT_FALSE(feedback(0).home_switch);
  vcd_->set_input_level(12, false);
  periods(5);
  EXPECT_FALSE(feedback(1).home_switch);
}

TEST_F(GpioInputs, BouncesShorterThanTheDebounceTimeAreIgnored) {
  for (int i = 0; i < 20; ++i) {
    vcd_->set_input_level(12, i % 2 == 0);  // joint 1 home
    periods(2);
    EXPECT_FALSE(feedback(1).home_switch);
  }
  vcd_->set_input_level(12, true);
  periods(5);
  EXPECT_TRUE(feedback(1).home_switch);
}

// The probe is not debounced: its first edge counts, and a touch shorter than a servo period
// is held until the servo thread has read it once.
TEST_F(GpioInputs, TheProbeLatchesItsFirstEdge) {
  EXPECT_FALSE(inputs().probe);
  vcd_->set_input_level(41, true);
  periods(1);
  vcd_->set_input_level(41, false);
  periods(20);
  EXPECT_TRUE(inputs().probe) << "a one-period touch is seen by the next read";
  EXPECT_FALSE(inputs().probe) << "and only by that one";
  vcd_->set_input_level(41, true);
  periods(1);
  EXPECT_TRUE(inputs().probe);
  EXPECT_TRUE(inputs().probe) << "held contact reads as contact";
}

TEST_F(GpioInputs, ActiveLowInputsAssertWhenTheLoopOpens) {
  vcd_->set_input_level(40, false);  // estop chain broken
  vcd_->set_input_level(13, false);  // joint 1 min limit wire cut
  periods(5);
  EXPECT_TRUE(inputs().estop);
  EXPECT_TRUE(feedback(1).min_limit);
  EXPECT_FALSE(feedback(0).min_limit);
}

// "gpio:!N" on a line key is "N" with the key's *_ACTIVE_LOW = 1, "gpio:N" is "N": both
// machines read the same levels the same way.
TEST(GpioConfig, AddressFormOfTheLineKeysReadsAsTheBareForm) {
  struct Form {
    std::string joint;
    std::string gpio;
  };
  const Form forms[] = {
      {"ENABLE_LINE = 2\nENABLE_ACTIVE_LOW = 1\nMIN_LIMIT_LINE = 3\nMIN_LIMIT_ACTIVE_LOW = 1\n"
       "MAX_LIMIT_LINE = 4\n",
       "ESTOP_LINE = 40\nESTOP_ACTIVE_LOW = 1\nPROBE_LINE = 41\n"},
      {"ENABLE_LINE = gpio:!2\nMIN_LIMIT_LINE = gpio:!3\nMAX_LIMIT_LINE = gpio:GPIO4\n",
       "ESTOP_LINE = gpio:!40\nPROBE_LINE = GPIO:41   # a touch plate\n"}};
  // What each machine reads, level by level: estop, probe, min limit, max limit.
  std::vector<std::vector<bool>> seen[2];
  // The levels the (inactive) enable line was written.
  std::vector<int> enable[2];
  for (int f = 0; f < 2; ++f) {
    TempDir dir;
    const auto loaded = load_machine(
        dir, 1, "DRIVER = gpio\nSCALE = 100\nSTEP_LINE = 0\nDIR_LINE = 1\n" + forms[f].joint,
        "[GPIO]\nCHIP = vcd:" + (dir.path() / "in.vcd").string() + "\n" + forms[f].gpio, kBaseNs);
    ASSERT_TRUE(loaded.ok());
    GpioDriver driver;
    driver.use_manual_clock(true);
    ASSERT_EQ(driver.configure(*loaded.config, {0}), "") << "form " << f;
    auto* vcd = dynamic_cast<drivers::VcdBackend*>(driver.backend());
    ASSERT_NE(vcd, nullptr);
    driver.enable();
    std::int64_t now_ns = 0;
    for (const bool level : {true, false, true}) {
      for (const int line : {3, 4, 40, 41})
        vcd->set_input_level(line, level);
      for (int i = 0; i < 5; ++i)
        driver.run_base_period(now_ns += kBaseNs);
      MachineInputs in;
      driver.read_inputs(in);
      JointFeedback fb[1];
      driver.read(fb, 1);
      seen[f].push_back({in.estop, in.probe, fb[0].min_limit, fb[0].max_limit});
    }
    driver.disable();
    for (const VcdChange& c : read_vcd(dir.path() / "in.vcd"))
      if (c.signal == "j0_enable") enable[f].push_back(c.level);
  }
  EXPECT_EQ(enable[1], enable[0]);
  ASSERT_FALSE(enable[0].empty());
  EXPECT_EQ(enable[0].back(), 1) << "an active-low enable is high while the machine is off";
  const std::vector<std::vector<bool>> expected = {
      {false, true, false, true}, {true, false, true, false}, {false, true, false, true}};
  EXPECT_EQ(seen[0], expected) << "the bare form with *_ACTIVE_LOW";
  EXPECT_EQ(seen[1], expected) << "the address form with '!'";
}

// The panel example writes its estop and enable lines as addresses; the driver takes them.
TEST(GpioConfig, ThePanelExamplesAddressesConfigureTheDriver) {
  TempDir dir;
  const std::filesystem::path ini = copy_example_machine(dir.path(), "gpio_panel_mill");
  std::string text = slurp(ini);
  const std::string chip = "CHIP = vcd:/tmp/cncd-panel.vcd";
  ASSERT_NE(text.find(chip), std::string::npos);
  text.replace(text.find(chip), chip.size(), "CHIP = vcd:" + (dir.path() / "p.vcd").string());
  dir.write(ini.filename().string(), text);
  const auto loaded = config::load_machine_config(ini);
  ASSERT_TRUE(loaded.ok());
  GpioDriver driver;
  driver.use_manual_clock(true);
  ASSERT_EQ(driver.configure(*loaded.config, {0, 1, 2}), "");
  auto* vcd = dynamic_cast<drivers::VcdBackend*>(driver.backend());
  ASSERT_NE(vcd, nullptr);
  driver.enable();
  std::int64_t now_ns = 0;
  for (const bool pressed : {false, true, false}) {
    vcd->set_input_level(4, pressed);  // ESTOP_LINE = gpio:GPIO4: high is pressed
    for (int i = 0; i < 5; ++i)
      driver.run_base_period(now_ns += loaded.config->base_period_ns);
    MachineInputs in;  // read_inputs only ever sets a flag: each driver adds its own
    driver.read_inputs(in);
    EXPECT_EQ(in.estop, pressed) << "pressed " << pressed;
  }
  driver.disable();
  std::map<std::string, int> level;
  for (const VcdChange& c : read_vcd(dir.path() / "p.vcd"))
    level[c.signal] = c.level;
  for (const char* enable : {"j0_enable", "j1_enable", "j2_enable"})
    EXPECT_EQ(level[enable], 1) << enable << ": gpio:! is active low, high while off";
}

TEST(GpioConfig, BadKeysAreReportedWithFileAndLine) {
  TempDir dir;
  const auto ini =
      dir.write("bad.ini",
                "[EMCMOT]\nSERVO_PERIOD = 1000000\n[KINS]\nKINEMATICS = trivkins\nJOINTS = 1\n"
                "[GPIO]\nCHIP = vcd:/tmp/x.vcd\nDEBOUNCE_NS = soon\n"
                "[JOINT_0]\nDRIVER = gpio\nSTEPLEN = -5\nDIR_LINE = 3\n");
  const auto result = config::load_machine_config(ini);
  ASSERT_FALSE(result.ok());
  std::vector<std::string> lines;
  for (const auto& p : result.problems)
    lines.push_back(p.to_string());
  for (const auto& p : result.warnings)
    lines.push_back(p.to_string());
  const auto has = [&](const std::string& text) {
    for (const auto& l : lines)
      if (l.find(text) != std::string::npos) return true;
    return false;
  };
  EXPECT_TRUE(has("bad.ini:8: [GPIO] DEBOUNCE_NS:"));
  EXPECT_TRUE(has("bad.ini:11: [JOINT_0] STEPLEN:"));
  EXPECT_TRUE(has("[JOINT_0] STEP_LINE: missing"));
  EXPECT_TRUE(has("bad.ini:10: [JOINT_0] DRIVER: DRIVER = gpio needs SCALE"));
  EXPECT_TRUE(has("bad.ini:10: [JOINT_0] DRIVER: DRIVER = gpio needs a base thread"));
}

TEST(GpioConfig, UnknownLinesAndDoubleUseFailConfigure) {
  TempDir dir;
  const auto loaded =
      load_machine(dir, 1, "DRIVER = gpio\nSCALE = 10\nSTEP_LINE = 5\nDIR_LINE = GPIO5\n",
                   "[GPIO]\nCHIP = vcd:" + (dir.path() / "x.vcd").string() + "\n", kBaseNs);
  ASSERT_TRUE(loaded.ok());
  GpioDriver driver;
  const std::string error = driver.configure(*loaded.config, {0});
  EXPECT_NE(error.find("machine.ini:"), std::string::npos) << error;
  EXPECT_NE(error.find("[JOINT_0] DIR_LINE: line GPIO5 is already used"), std::string::npos)
      << error;
}

}  // namespace
}  // namespace cncd::test
