// The parameter file and [TRAJ] POSITION_FILE across SIGTERM, kill -9 and corrupt files, with
// the real daemon.
#include <signal.h>

#include <atomic>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Every line of `text` as numbers; fails the test on a line that is not `fields` numbers.
std::vector<std::vector<double>> numbers(const std::string& text, std::size_t fields,
                                         const std::string& name) {
  std::vector<std::vector<double>> rows;
  EXPECT_FALSE(text.empty()) << name << " is empty";
  EXPECT_TRUE(text.empty() || text.back() == '\n') << name << " is cut short:\n" << text;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    std::vector<double> row(fields);
    for (auto& value : row)
      EXPECT_TRUE(static_cast<bool>(in >> value)) << name << ": bad line '" << line << "'";
    rows.push_back(row);
  }
  return rows;
}

class PersistDaemonTest : public ::testing::Test {
 protected:
  void SetUp() override { ini_ = copy_example_machine(dir_.path()); }

  std::string start() {
    const std::string error = daemon_.start(dir_.path(), {"--ini", ini_.string()});
    if (!error.empty()) return error;
    return client_.connect(daemon_.socket());
  }
  json call(const std::string& method, const json& params = nullptr) {
    return client_.call(method, params, 30000);
  }
  json wait_idle() {
    json s;
    for (int i = 0; i < 3000; ++i) {
      s = result_of(call("status.get"));
      if (s["motion"] == "idle") break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return s;
  }
  void ready_and_move(double x, double y, double z) {
    result_of(call("machine.reset"));
    result_of(call("machine.on"));
    result_of(call("machine.home"));
    wait_idle();
    std::ostringstream line;
    line << "G53 G0 X" << x << " Y" << y << " Z" << z;
    result_of(call("mdi.execute", {{"line", line.str()}}));
  }
  fs::path position_file() const { return dir_.path() / "sim_mm.position"; }
  fs::path parameter_file() const { return dir_.path() / "sim_mm.var"; }

  TempDir dir_;
  fs::path ini_;
  DaemonProcess daemon_;
  daemon::Client client_;
};

TEST_F(PersistDaemonTest, SigtermSavesBothFilesAndARestartStandsThereUnhomed) {
  ASSERT_EQ(start(), "");
  EXPECT_EQ(result_of(call("status.get"))["position_restored"], "none");
  ready_and_move(12.5, 30.25, -4);
  result_of(call("mdi.execute", {{"line", "G10 L2 P2 X7.5"}}));
  EXPECT_EQ(daemon_.stop(), 0);

  const auto positions = numbers(slurp(position_file()), 1, "position file");
  ASSERT_EQ(positions.size(), 3u);
  EXPECT_NEAR(positions[0][0], 12.5, 1e-6);
  EXPECT_NEAR(positions[1][0], 30.25, 1e-6);
  EXPECT_NEAR(positions[2][0], -4, 1e-6);
  EXPECT_NE(slurp(parameter_file()).find("5241\t7.5"), std::string::npos);

  ASSERT_EQ(start(), "");
  const auto s = result_of(call("status.get"));
  EXPECT_EQ(s["position_restored"], "clean");
  EXPECT_NEAR(s["position"]["actual"]["x"].get<double>(), 12.5, 1e-6) << s.dump();
  EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 30.25, 1e-6);
  EXPECT_NEAR(s["position"]["actual"]["z"].get<double>(), -4, 1e-6);
  for (const auto& homed : s["homed"])
    EXPECT_FALSE(homed.get<bool>());
  // Turning on does not move the machine from there.
  result_of(call("machine.reset"));
  result_of(call("machine.on"));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const auto on = result_of(call("status.get"));
  EXPECT_EQ(on["fault"], "");
  EXPECT_NEAR(on["position"]["actual"]["x"].get<double>(), 12.5, 1e-6);
  EXPECT_EQ(daemon_.stop(), 0);
}

// The position file is kept up to date while the machine moves: kill -9 in the middle of a
// long move, and the restart stands where the machine was at most a couple of seconds before,
// saying that the positions come from a run that did not shut down.
TEST_F(PersistDaemonTest, KillNineWhileMovingRestartsNearTheLastPositionFlaggedUnclean) {
  ASSERT_EQ(start(), "");
  result_of(call("machine.reset"));
  result_of(call("machine.on"));
  result_of(call("machine.home"));
  wait_idle();
  // 6 mm/s along X: 40 s to the end, killed after about 5.
  const fs::path program = dir_.write("slow.ngc", "G90 G1 F360 X240\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  result_of(call("program.run"));
  const auto started = std::chrono::steady_clock::now();
  json last;
  while (std::chrono::steady_clock::now() - started < std::chrono::milliseconds(5200)) {
    last = result_of(call("status.get"));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(last["exec"], "running") << last.dump();
  daemon_.kill_hard();
  const double x_last = last["position"]["actual"]["x"].get<double>();
  ASSERT_GT(x_last, 20.0) << last.dump();

  ASSERT_EQ(start(), "");
  const auto s = result_of(call("status.get"));
  EXPECT_EQ(s["position_restored"], "unclean") << s.dump();
  const double x = s["position"]["actual"]["x"].get<double>();
  // Saved every 2 s while moving: no further back than that, with a margin for a loaded
  // machine, and never ahead of the last status seen.
  EXPECT_LE(x, x_last + 1.0) << s.dump();
  EXPECT_GE(x, x_last - 6.0 * 3.0) << "restored X " << x << ", last seen " << x_last;
  EXPECT_NEAR(s["position"]["actual"]["y"].get<double>(), 0.0, 1e-6);
  for (const auto& homed : s["homed"])
    EXPECT_FALSE(homed.get<bool>());
  // An orderly stop after that: clean again.
  EXPECT_EQ(daemon_.stop(), 0);
  ASSERT_EQ(start(), "");
  EXPECT_EQ(result_of(call("status.get"))["position_restored"], "clean");
}

// At rest the file is written at once, so that a kill -9 right after a move keeps its end.
TEST_F(PersistDaemonTest, KillNineAfterAMoveRestartsWhereTheMoveEnded) {
  ASSERT_EQ(start(), "");
  ready_and_move(33.25, 44.5, -5);
  // Saved at rest, and again once the feedback has settled (a quarter of a second).
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  daemon_.kill_hard();
  const auto positions = numbers(slurp(position_file()), 1, "position file");
  ASSERT_EQ(positions.size(), 3u);
  EXPECT_NEAR(positions[0][0], 33.25, 1e-6);
  EXPECT_NEAR(positions[1][0], 44.5, 1e-6);
  EXPECT_NEAR(positions[2][0], -5, 1e-6);
  EXPECT_TRUE(fs::exists(position_file().string() + ".running"));
  ASSERT_EQ(start(), "");
  const auto s = result_of(call("status.get"));
  EXPECT_EQ(s["position_restored"], "unclean");
  EXPECT_NEAR(s["position"]["actual"]["x"].get<double>(), 33.25, 1e-6) << s.dump();
  const CommandResult shown = run_command({CNCCTL_BINARY, "--socket", daemon_.socket(), "status"});
  EXPECT_NE(shown.out.find("unclean shutdown"), std::string::npos) << shown.out;
}

TEST_F(PersistDaemonTest, CorruptPositionFileIsNamedWithItsLineAndStopsTheStart) {
  std::ofstream(position_file()) << "1.0\nbanana\n3.0\n";
  const std::string error = start();
  EXPECT_NE(error.find("status 78"), std::string::npos) << error;
  EXPECT_NE(error.find("sim_mm.position:2"), std::string::npos) << error;
  EXPECT_EQ(slurp(position_file()), "1.0\nbanana\n3.0\n");  // left for the user to see
}

TEST_F(PersistDaemonTest, CorruptParameterFileIsNamedWithItsLineAndStopsTheStart) {
  const std::string corrupt = "5161\t0.0\n5221\n";
  std::ofstream(parameter_file()) << corrupt;
  const std::string error = start();
  EXPECT_NE(error.find("status 78"), std::string::npos) << error;
  EXPECT_NE(error.find("sim_mm.var:2"), std::string::npos) << error;
  EXPECT_EQ(slurp(parameter_file()), corrupt);
}

// kill -9 while parameters are saved after every MDI block, or while the daemon shuts down:
// each file is always the old or the new content, and the daemon always starts again.
TEST_F(PersistDaemonTest, KillNineAtRandomMomentsNeverLeavesAFileCorrupt) {
  std::mt19937 random(20261123);
  int written = 0;
  for (int round = 0; round < 20; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    ASSERT_EQ(start(), "");
    const auto s = result_of(call("status.get"));
    if (fs::exists(position_file())) {
      const auto saved = numbers(slurp(position_file()), 1, "position file");
      ASSERT_EQ(saved.size(), 3u);
      EXPECT_NEAR(s["position"]["actual"]["x"].get<double>(), saved[0][0], 1e-6);
    }
    ready_and_move(round, round, -round);
    const bool during_shutdown = round % 2 == 1;
    std::atomic<int> sent{written};
    std::thread writer([&] {
      try {
        for (int i = written + 1; i < written + 10000; ++i) {
          sent = i;
          client_.call("mdi.execute", {{"line", "G10 L2 P1 X" + std::to_string(i)}}, 5000);
        }
      } catch (const std::exception&) {
        // The daemon was killed.
      }
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(random() % 60));
    if (during_shutdown) {
      daemon_.signal(SIGTERM);
      std::this_thread::sleep_for(std::chrono::microseconds(random() % 20000));
    }
    daemon_.kill_hard();
    writer.join();
    written = sent;

    const auto parameters = numbers(slurp(parameter_file()), 2, "parameter file");
    bool found = false;
    for (const auto& row : parameters) {
      if (row[0] != 5221) continue;
      found = true;
      EXPECT_GE(row[1], 0);
      EXPECT_LE(row[1], written);
    }
    EXPECT_TRUE(found);
    if (fs::exists(position_file())) {
      EXPECT_EQ(numbers(slurp(position_file()), 1, "position file").size(), 3u);
    }
  }
  ASSERT_EQ(start(), "");
  EXPECT_EQ(daemon_.stop(), 0);
}

}  // namespace
}  // namespace cncd::test
