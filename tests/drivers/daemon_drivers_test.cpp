// The real cncd process runs the G81 example on the simulated, the step/dir (recorded) and the
// Modbus machine (against the cncd-drive-sim executable); all must end at the same place.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <regex>
#include <thread>

#include <gtest/gtest.h>

#include "client.hpp"
#include "client_checks.hpp"
#include "daemon_process.hpp"
#include "daemon_util.hpp"
#include "test_util.hpp"
#include "vfd_server.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

const std::string kProgram = std::string(CNCD_SOURCE_DIR) + "/examples/g81_example1.ngc";

// cncd-drive-sim on a free loopback port, stopped on destruction. It serves at real-time
// priority where permitted: real drives have processors of their own, and a simulator kept
// waiting by the other tests on a busy machine would answer after the bus timeout.
class DriveSimProcess {
 public:
  // `port` 0 picks a free one; `extra` are further options (--fault-after 0).
  std::string start(int port = 0, const std::vector<std::string>& extra = {}) {
    const std::string port_text = std::to_string(port);
    int out[2];
    if (pipe(out) != 0) return "pipe failed";
    pid_ = fork();
    if (pid_ == 0) {
      dup2(out[1], STDOUT_FILENO);
      close(out[0]);
      std::vector<std::string> args = {DRIVE_SIM_BINARY, "--port", port_text,       "--drives", "3",
                                       "--lag",          "0.005",  "--rt-priority", "60"};
      args.insert(args.end(), extra.begin(), extra.end());
      std::vector<char*> argv;
      for (auto& arg : args)
        argv.push_back(arg.data());
      argv.push_back(nullptr);
      execv(DRIVE_SIM_BINARY, argv.data());
      _exit(127);
    }
    close(out[1]);
    std::string line;
    char c = 0;
    while (read(out[0], &c, 1) == 1 && c != '\n')
      line += c;
    // Kept open: what it prints later (a fault set or cleared) must not meet a closed pipe.
    out_fd_ = out[0];
    std::smatch m;
    if (!std::regex_search(line, m, std::regex(":([0-9]+)$"))) {
      stop(SIGTERM);
      return "no port in: " + line;
    }
    port_ = std::stoi(m[1]);
    return "";
  }
  ~DriveSimProcess() { stop(SIGTERM); }
  // Ends the drives' process with `signal` (SIGKILL: the drives vanish mid-conversation).
  void stop(int signal) {
    if (pid_ > 0) {
      kill(pid_, signal);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
    if (out_fd_ >= 0) close(out_fd_);
    out_fd_ = -1;
  }
  int port() const { return port_; }
  // SIGUSR1 toggles a fault on every drive.
  void signal(int signal) const { kill(pid_, signal); }

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  int out_fd_ = -1;
};

// Runs the example program on `ini` (already adapted) and returns the final status.
json run_example(const TempDir& dir, const std::string& ini,
                 const std::string& program = kProgram) {
  DaemonProcess daemon;
  const std::string error = daemon.start(dir.path(), {"--ini", ini});
  EXPECT_EQ(error, "");
  if (!error.empty()) return json();
  daemon::Client client;
  EXPECT_EQ(client.connect(daemon.socket()), "");
  const auto wait_until = [&](auto done) { return wait_for(client, daemon, 60, done); };
  make_ready(client, daemon);
  result(client.call("program.open", {{"path", program}}));
  result(client.call("program.run"));
  wait_until([](const json& s) { return s["exec"] == "idle"; });
  // Let the drives settle onto the last command.
  json settled = wait_until([](const json& s) {
    const auto& a = s["position"]["actual"];
    const auto& c = s["position"]["commanded"];
    for (const char* axis : {"x", "y", "z"}) {
      if (std::abs(a[axis].get<double>() - c[axis].get<double>()) > 1e-3) return false;
    }
    return true;
  });
  // A clean stop, so that the drivers close what they write (a recording's last transitions).
  EXPECT_EQ(daemon.stop(), 0) << daemon.log();
  return settled;
}

// The Modbus example pointed at the drive simulator on `port`, with the example's own
// following-error limits. The simulator is an ordinary process on a machine shared with other
// tests, and the bus thread is no real-time thread: their replies can come tens of
// milliseconds late. The servo loop compares each readback with the setpoint it answers
// (JointFeedback::command_cycle), so that latency is not taken for a drive that cannot follow.
std::vector<std::pair<std::string, std::string>> modbus_changes(int port) {
  return {{"PORT = 1502", "PORT = " + std::to_string(port)}};
}

// The step/dir mill recording to `vcd`, with `more` changes. A base thread stalled by a busy
// shared machine catches up afterwards, which the example's tight following-error limits
// would call a fault: they are widened.
std::string recorded_mill(const TempDir& dir, const std::string& vcd,
                          std::vector<std::pair<std::string, std::string>> more = {}) {
  more.insert(more.begin(), {{"CHIP = vcd:/tmp/cncd-steps.vcd", "CHIP = vcd:" + vcd},
                             {"FERROR = 1\n", "FERROR = 10\n"},
                             {"MIN_FERROR = 0.25\n", "MIN_FERROR = 2\n"}});
  return adapt(dir, "gpio_vcd_mill.ini", more);
}

void expect_end(const json& s, const char* driver) {
  SCOPED_TRACE(driver);
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  for (const auto& [axis, end] : {std::pair{"x", 4.0}, {"y", 5.0}, {"z", 3.0}}) {
    EXPECT_NEAR(s["position"]["commanded"][axis].get<double>(), end, 1e-9) << axis;
    EXPECT_NEAR(s["position"]["actual"][axis].get<double>(), end, 1e-3) << axis;
  }
}

TEST(DriversEndToEnd, SimGpioAndModbusRunTheExampleToTheSameEnd) {
  {
    TempDir dir;
    expect_end(run_example(dir, adapt(dir, "sim_mm.ini", {})), "sim");
  }
  {
    TempDir dir;
    const std::string vcd = (dir.path() / "steps.vcd").string();
    const json s = run_example(dir, recorded_mill(dir, vcd));
    expect_end(s, "gpio");
    // cncd has stopped and flushed the recording: the pulses add up to the end position.
    const auto changes = read_vcd(vcd);
    EXPECT_EQ(step_stats(changes, 0).net_steps, 4 * 320);
    EXPECT_EQ(step_stats(changes, 1).net_steps, 5 * 320);
    EXPECT_EQ(step_stats(changes, 2).net_steps, 3 * 320);
    EXPECT_GE(step_stats(changes, 0).min_high_ns, 5000);
  }
  {
    DriveSimProcess sim;
    ASSERT_EQ(sim.start(), "");
    TempDir dir;
    const json s = run_example(dir, adapt(dir, "modbus_sim.ini", modbus_changes(sim.port())));
    expect_end(s, "modbus");
  }
}

// The recording is of the joints, whatever the kinematics: the step/dir mill made a corexy
// machine runs the example to X4 Y5 Z3, and its two belt motors' pulses add up to X + Y and
// X - Y, not to X and Y (docs/kinematics.md).
TEST(DriversEndToEnd, TheRecordingOfACorexyMachineHasItsMotorsSteps) {
  TempDir dir;
  const std::string vcd = (dir.path() / "steps.vcd").string();
  const json s = run_example(
      dir, recorded_mill(dir, vcd,
                         {{"KINEMATICS = trivkins coordinates=XYZ", "KINEMATICS = corexykins"},
                          // The motors' ranges while X and Y keep within their limits.
                          {"STEPGEN_MAXACCEL = 600\nMIN_LIMIT = -10\nMAX_LIMIT = 300\n",
                           "STEPGEN_MAXACCEL = 600\nMIN_LIMIT = -20\nMAX_LIMIT = 500\n"},
                          {"STEPGEN_MAXACCEL = 600\nMIN_LIMIT = -10\nMAX_LIMIT = 200\n",
                           "STEPGEN_MAXACCEL = 600\nMIN_LIMIT = -210\nMAX_LIMIT = 310\n"}}));
  expect_end(s, "gpio corexy");
  EXPECT_EQ(s["joints"][0]["commanded"], 9.0) << s["joints"].dump();
  EXPECT_EQ(s["joints"][1]["commanded"], -1.0);
  const auto changes = read_vcd(vcd);
  EXPECT_EQ(step_stats(changes, 0).net_steps, 9 * 320);   // X + Y
  EXPECT_EQ(step_stats(changes, 1).net_steps, -1 * 320);  // X - Y
  EXPECT_EQ(step_stats(changes, 2).net_steps, 3 * 320);
}

// The first time `signal` goes to `level` at or after `from`, or -1.
std::int64_t first_edge(const std::vector<VcdChange>& changes, const std::string& signal, int level,
                        std::int64_t from = 0) {
  for (const auto& c : changes) {
    if (c.signal == signal && c.level == level && c.time_ns >= from && c.time_ns > 0)
      return c.time_ns;
  }
  return -1;
}

TEST(DriversEndToEnd, TheRecordingShowsTheSpindleCoolantAndOutputsAgainstTheSteps) {
  TempDir dir;
  const std::string vcd = (dir.path() / "steps.vcd").string();
  const auto program = dir.write("spindle.ngc",
                                 "G21 G17 G90 G94\n"
                                 "F100\n"
                                 "G0 X1 Y2 Z3\n"
                                 "M3 S1000\n"
                                 "M8\n"
                                 "M62 P0\n"
                                 "G1 X2 F600\n"
                                 "G90 G81 G98 X4 Y5 Z1.5 R2.8\n"
                                 "G80\n"
                                 "M9\n"
                                 "M5\n"
                                 "M2\n");
  const json s = run_example(dir, recorded_mill(dir, vcd), program.string());
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  const auto changes = read_vcd(vcd);
  const std::int64_t enabled = first_edge(changes, "spindle_enable", 1);
  ASSERT_GT(enabled, 0);
  // The feed after M3 waits for the spindle's ramp (8000 rpm/s) to 950 rpm: 0.119 s.
  const std::int64_t first_x_step = first_edge(changes, "j0_step", 1, enabled);
  ASSERT_GT(first_x_step, 0);
  EXPECT_GE(first_x_step - enabled, 110'000'000);
  // M62 P0 goes on as that move starts, before its first step (3.5 ms in at 500 mm/s^2).
  const std::int64_t dout = first_edge(changes, "dout0", 1);
  ASSERT_GT(dout, 0);
  EXPECT_LE(dout, first_x_step);
  EXPECT_LT(first_x_step - dout, 10'000'000);
  // The drill goes down only with the spindle on, and the PWM runs while it is.
  const std::int64_t first_z_feed_step = first_edge(changes, "j2_step", 1, first_x_step);
  EXPECT_GT(first_z_feed_step, enabled);
  EXPECT_GT(first_edge(changes, "spindle_pwm", 1, enabled), 0);
  // M8 before the moves, M9 and M5 after them.
  const std::int64_t flood_on = first_edge(changes, "flood", 1);
  ASSERT_GT(flood_on, 0);
  EXPECT_LT(flood_on, first_x_step);
  const std::int64_t flood_off = first_edge(changes, "flood", 0, flood_on);
  const std::int64_t disabled = first_edge(changes, "spindle_enable", 0, enabled);
  EXPECT_GT(flood_off, first_z_feed_step);
  EXPECT_GE(disabled, flood_off);
}

TEST(DriversEndToEnd, KilledModbusDrivesLatchAFaultAndTheDaemonCarriesOn) {
  DriveSimProcess sim;
  ASSERT_EQ(sim.start(), "");
  const int port = sim.port();
  TempDir dir;
  const std::string ini = adapt(dir, "modbus_sim.ini", modbus_changes(port));
  DaemonProcess daemon;
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", ini}), "");
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon.socket()), "");
  const auto wait_until = [&](auto done) { return wait_for(client, daemon, 30, done); };
  const auto home = [&] {
    result(client.call("machine.home"));
    wait_until([](const json& s) {
      for (const auto& h : s["homed"])
        if (!h.get<bool>()) return false;
      return s["motion"] == "idle";
    });
  };
  result(client.call("machine.reset"));
  result(client.call("machine.on"));
  home();
  const auto program = dir.write("long.ngc", "G21 G90 G1 F3000 X200\nM2\n");
  result(client.call("program.open", {{"path", program.string()}}));
  result(client.call("program.run"));
  wait_until([](const json& s) { return s["position"]["commanded"]["x"].get<double>() > 5.0; });

  sim.stop(SIGKILL);
  const json faulted =
      wait_until([](const json& s) { return !s["fault"].get<std::string>().empty(); });
  EXPECT_NE(faulted["state"], "on");
  EXPECT_NE(faulted["fault"].get<std::string>().find("modbus"), std::string::npos)
      << faulted["fault"];
  // The fault event names the servo thread's code; the failed exchanges are counted.
  const json events = result(client.call("errors.list"))["events"];
  const auto fault = std::find_if(events.begin(), events.end(),
                                  [](const json& e) { return e["kind"] == "fault"; });
  ASSERT_NE(fault, events.end()) << events.dump();
  EXPECT_TRUE(fault->value("code", "") == "drive_fault" ||
              fault->value("code", "") == "feedback_stale")
      << fault->dump();
  EXPECT_GT(result(client.call("status.get"))["rt"]["modbus_errors"].get<double>(), 0);
  const json stopped = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_NE(stopped["program"]["result"], "done");
  // The daemon is alive and commands nothing further.
  expect_stopped_short_of_x200(client, stopped, std::chrono::milliseconds(300));

  // The drives come back: after an explicit reset the machine runs again. The port may stay
  // taken for a moment by the daemon's own reconnection attempts (a loopback connection to a
  // port nobody listens on can land on itself until the daemon drops it), so try for a while.
  std::string restarted = sim.start(port);
  for (int attempt = 0; !restarted.empty() && attempt < 50; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    restarted = sim.start(port);
  }
  ASSERT_EQ(restarted, "");
  const json refused = client.call("program.run");
  EXPECT_TRUE(refused.contains("error")) << refused.dump();
  if (result(client.call("status.get"))["state"] == "estop") result(client.call("machine.reset"));
  // Until the restarted drives answer, turning on trips over their stale or moved feedback;
  // an operator tries again, and so does this test.
  wait_until([&](const json&) {
    client.call("machine.on");
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const json s = result(client.call("status.get"));
    return s["state"] == "on" && s["fault"] == "";
  });
  home();
  const auto back = dir.write("back.ngc", "G21 G90 G1 F3000 X20 Y10\nM2\n");
  result(client.call("program.open", {{"path", back.string()}}));
  result(client.call("program.run"));
  const json done = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(done["program"]["result"], "done") << done.dump();
  EXPECT_EQ(done["position"]["commanded"]["x"], 20.0);
}

// Drives whose fault bit is set: machine.on answers with the fault, naming the joint, the drive
// and why, and the machine stays off; once the drives are fine, it comes on.
TEST(DriversEndToEnd, MachineOnWithAFaultedModbusDriveIsAnErrorNamingIt) {
  DriveSimProcess sim;
  ASSERT_EQ(sim.start(0, {"--fault-after", "0"}), "");
  TempDir dir;
  const std::string ini = adapt(dir, "modbus_sim.ini", modbus_changes(sim.port()));
  DaemonProcess daemon;
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", ini}), "");
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon.socket()), "");
  result(client.call("machine.reset"));
  const json r = client.call("machine.on");
  ASSERT_TRUE(r.contains("error")) << r.dump();
  EXPECT_EQ(r["error"]["code"], 1008);
  const std::string message = r["error"]["message"];
  EXPECT_NE(message.find("joint "), std::string::npos) << message;
  EXPECT_NE(message.find("drive fault"), std::string::npos) << message;
  EXPECT_NE(message.find("modbus MODBUS_0 slave"), std::string::npos) << message;
  EXPECT_NE(message.find("drive reports a fault"), std::string::npos) << message;
  EXPECT_EQ(result(client.call("status.get"))["state"], "off");

  sim.signal(SIGUSR1);  // the fault is cleared
  json on;
  for (int attempt = 0; attempt < 100; ++attempt) {
    on = client.call("machine.on");
    if (on.contains("result")) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(on.contains("result")) << on.dump();
  EXPECT_EQ(result(client.call("status.get"))["state"], "on");
}

TEST(DriversEndToEnd, ASimulatedMotorThatLagsTripsTheFollowingError) {
  TempDir dir;
  const std::string ini = adapt(dir, "sim_mm.ini", {{"[JOINT_0]\n", "[JOINT_0]\nSIM_LAG = 0.5\n"}});
  DaemonProcess daemon;
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", ini}), "");
  daemon::Client client;
  ASSERT_EQ(client.connect(daemon.socket()), "");
  result(client.call("machine.reset"));
  result(client.call("machine.on"));
  result(client.call("machine.home"));
  const auto wait_until = [&](auto done) { return wait_for(client, daemon, 30, done); };
  wait_until([](const json& s) { return s["homed"][0] == true && s["motion"] == "idle"; });
  const auto program = dir.write("lag.ngc", "G21 G90 G1 F3000 X50\nM2\n");
  result(client.call("program.open", {{"path", program.string()}}));
  result(client.call("program.run"));
  const json end = wait_until([](const json& s) { return s["exec"] == "idle"; });
  EXPECT_EQ(end["program"]["result"], "aborted") << end.dump();
  EXPECT_NE(end["fault"].get<std::string>().find("joint 0: following error"), std::string::npos)
      << end["fault"];
  EXPECT_EQ(end["state"], "off");
  EXPECT_EQ(end["joint_fault"][0], true);
  EXPECT_LT(end["position"]["commanded"]["x"].get<double>(), 50.0);
}

TEST(DriversEndToEnd, ARigidTapRunsOnAModbusServoSpindle) {
  // The loopback drive turns by the wall clock: a stop sent 50 ms late by a bus thread kept
  // waiting lets it run the tap's 0.25 rev bound (at 300 rpm) past the end.
  if (!realtime_scheduling_permitted()) GTEST_SKIP() << kNoRealtime;
  // The sim mill with its spindle on Modbus TCP: a servo spindle with a 32-bit position
  // counter, read every 5 ms, ramping at 3000 rpm/s.
  VfdServer server(servo_spindle_map(), 3);
  ASSERT_EQ(server.start(), "");
  TempDir dir;
  const std::string ini =
      modbus_spindle_ini(dir, server.port(), 5, "POSITION_REGISTER = 10\nPOSITION_SCALE = 4096\n");
  const std::string program = dir.write("tap.ngc",
                                        "G21 G90\nG0 X10 Y10 Z5\nM3 S300\nG33.1 Z-5 K1.25\n"
                                        "G1 X20 F600\nM5\nM2\n")
                                  .string();
  DaemonProcess daemon;
  daemon::Client client;
  run_on_new_daemon(daemon, client, dir, ini, program);
  if (::testing::Test::HasFatalFailure()) return;
  // Judged by the outcome and the drive, not status polls that a loaded machine may delay.
  const json end = wait_for(client, daemon, 60, [&](const json& s) {
    return s["exec"] == "idle" && s["program"]["result"] != "";
  });
  EXPECT_EQ(end["program"]["result"], "done") << end.dump() << daemon.log();
  EXPECT_EQ(end["fault"], "") << end.dump();
  EXPECT_NEAR(end["position"]["commanded"]["z"].get<double>(), 5, 1e-9);
  EXPECT_NEAR(end["position"]["commanded"]["x"].get<double>(), 20, 1e-9);
  for (int i = 0; i < 2000 && server.holding(0) != 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(server.holding(0), 0);
  // The shaft turned 10 mm / 1.25 mm = 8 revolutions into the hole from where it stood (at 0,
  // or where the tap stopped an M3 that had begun), and back there within the tap's 0.25 rev.
  const std::vector<double> turns = server.turning_points();
  const auto bottom = std::max_element(turns.begin(), turns.end());
  ASSERT_TRUE(bottom != turns.end() && bottom + 1 != turns.end())
      << ::testing::PrintToString(turns);
  const double top = bottom == turns.begin() ? 0.0 : *(bottom - 1);
  EXPECT_NEAR(*bottom - top, 8.0, 0.25) << ::testing::PrintToString(turns);
  EXPECT_NEAR(*(bottom + 1), top, 0.25) << ::testing::PrintToString(turns);
  // The drive was told forward, reverse in the hole, forward again and stop.
  EXPECT_GE(server.writes(0), 5);
  EXPECT_EQ(daemon.stop(), 0) << daemon.log();
}

}  // namespace
}  // namespace cncd::test
