// A USB pendant on the real daemon: [PANEL] keys on an evdev device that is a FIFO here, fed
// recorded `struct input_event` records as a ShuttleXpress or a keypad sends them. A held key
// jogs X and its release stops it; another key is cycle start and runs the open G81 example to
// X4 Y5 Z3. The writer going away is a warning event, and the device is read again when it
// comes back.
#include <fcntl.h>
#include <linux/input.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class PendantTest : public MachineTest {
 protected:
  void SetUp() override {
    fifo_ = dir_.path() / "pendant";
    ASSERT_EQ(::mkfifo(fifo_.c_str(), 0600), 0);
    ini_ = copy_example_machine(dir_.path());
    std::ofstream(ini_, std::ios::app) << "\n[PANEL]\nDEBOUNCE_MS = 5\n"
                                       << "CYCLE_START = evdev:" << fifo_.string() << ":KEY_F1\n"
                                       << "JOG_X_PLUS = evdev:" << fifo_.string() << ":KEY_F2\n";
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
    ASSERT_NO_FATAL_FAILURE(open_writer());
  }
  void TearDown() override {
    if (writer_ >= 0) ::close(writer_);
  }

  // The pendant plugged in: a writer on the FIFO once cncd reads it.
  void open_writer() {
    for (int i = 0; i < 1000 && writer_ < 0; ++i) {
      writer_ = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
      if (writer_ < 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_GE(writer_, 0) << "cncd never opened " << fifo_;
  }
  void key(std::uint16_t code, int value) {
    input_event events[2]{};
    events[0].type = EV_KEY;
    events[0].code = code;
    events[0].value = value;
    events[1].type = EV_SYN;
    events[1].code = SYN_REPORT;
    ASSERT_EQ(::write(writer_, events, sizeof events), static_cast<ssize_t>(sizeof events));
  }
  json until_input(const std::string& key_name, bool on) {
    return wait_until([&](const json& s) { return s["panel"]["inputs"][key_name] == on; },
                      std::chrono::seconds(10));
  }

  std::filesystem::path fifo_;
  int writer_ = -1;
};

TEST_F(PendantTest, AHeldKeyJogsXAndAnotherIsCycleStart) {
  ready_machine();
  const double x0 = status()["position"]["commanded"]["x"].get<double>();
  ASSERT_NO_FATAL_FAILURE(key(KEY_F2, 1));
  EXPECT_EQ(until_input("JOG_X_PLUS", true)["panel"]["inputs"]["JOG_X_PLUS"], true);
  const json moving = wait_until(
      [&](const json& s) { return s["position"]["commanded"]["x"].get<double>() > x0 + 1; });
  EXPECT_GT(moving["position"]["commanded"]["x"].get<double>(), x0 + 1);
  ASSERT_NO_FATAL_FAILURE(key(KEY_F2, 0));
  const json rest = wait_until([](const json& s) { return s["motion"] == "idle"; });
  const double x1 = rest["position"]["commanded"]["x"].get<double>();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(status()["position"]["commanded"]["x"].get<double>(), x1) << "the release stops it";

  std::ifstream seed(std::filesystem::path(CNCD_SOURCE_DIR) / "examples/g81_example1.ngc");
  std::stringstream text;
  text << seed.rdbuf();
  const auto program = dir_.write("g81_example1.ngc", text.str());
  result_of(call("program.open", {{"path", program.string()}}));
  wait_until([](const json& s) { return s["program"]["opening"] == ""; });
  ASSERT_NO_FATAL_FAILURE(key(KEY_F1, 1));
  ASSERT_NO_FATAL_FAILURE(key(KEY_F1, 0));
  wait_until([](const json& s) { return s["exec"] == "running"; }, std::chrono::seconds(10));
  const json done = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(done["program"]["result"], "done") << done.dump();
  EXPECT_DOUBLE_EQ(done["position"]["commanded"]["x"].get<double>(), 4);
  EXPECT_DOUBLE_EQ(done["position"]["commanded"]["y"].get<double>(), 5);
  EXPECT_DOUBLE_EQ(done["position"]["commanded"]["z"].get<double>(), 3);
}

TEST_F(PendantTest, AnUnpluggedPendantIsAWarningAndIsReadAgainWhenItComesBack) {
  ready_machine();
  ASSERT_NO_FATAL_FAILURE(key(KEY_F2, 1));
  until_input("JOG_X_PLUS", true);
  const std::uint64_t since = result_of(call("errors.list"))["last_seq"];
  ::close(writer_);  // unplugged with the key held: the key reads released, the jog stops
  writer_ = -1;
  const json rest = wait_until([](const json& s) {
    return s["panel"]["inputs"]["JOG_X_PLUS"] == false && s["motion"] == "idle";
  });
  EXPECT_EQ(rest["motion"], "idle");
  bool warned = false;
  for (int i = 0; i < 500 && !warned; ++i) {
    const json events = result_of(call("errors.list", {{"since", since}}))["events"];
    for (const auto& e : events) {
      if (e["kind"] == "driver" && e["level"] == "warning" &&
          e["message"].get<std::string>().find("pendant: lost") != std::string::npos)
        warned = true;
    }
    if (!warned) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(warned) << result_of(call("errors.list", {{"since", since}})).dump();
  ASSERT_NO_FATAL_FAILURE(open_writer());
  ASSERT_NO_FATAL_FAILURE(key(KEY_F2, 1));
  EXPECT_EQ(until_input("JOG_X_PLUS", true)["panel"]["inputs"]["JOG_X_PLUS"], true);
  ASSERT_NO_FATAL_FAILURE(key(KEY_F2, 0));
  until_input("JOG_X_PLUS", false);
}

}  // namespace
}  // namespace cncd::test
