// The daemon's state files in a state directory: the example machine run in place leaves its
// directory as it was, and files that do not exist yet start from the defaults and are
// created, as LinuxCNC does.
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Every file of a directory with its content.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir))
    files[entry.path().filename().string()] = slurp(entry.path());
  return files;
}

// The value of parameter `number` in a parameter file, or NaN.
double parameter(const fs::path& file, int number) {
  std::istringstream lines(slurp(file));
  int n = 0;
  double value = 0;
  while (lines >> n >> value) {
    if (n == number) return value;
  }
  return std::nan("");
}

class StateDirDaemonTest : public ::testing::Test {
 protected:
  std::string start(const fs::path& ini, std::vector<std::string> args = {}) {
    args.insert(args.begin(), {"--ini", ini.string()});
    if (const auto error = daemon_.start(dir_.path(), args); !error.empty()) return error;
    return client_.connect(daemon_.socket());
  }
  json call(const std::string& method, const json& params = nullptr) {
    return client_.call(method, params, 30000);
  }
  void ready() {
    result_of(call("machine.reset"));
    result_of(call("machine.on"));
    result_of(call("machine.home"));
    for (int i = 0; i < 2000 && result_of(call("status.get"))["motion"] != "idle"; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  json mdi(const std::string& line) { return call("mdi.execute", {{"line", line}}); }

  TempDir dir_;
  DaemonProcess daemon_;
  daemon::Client client_;
};

TEST_F(StateDirDaemonTest, TheExampleRunInPlaceKeepsItsStateInXdgStateHomeAndItsDirectoryAsItWas) {
  const fs::path examples = fs::path(CNCD_SOURCE_DIR) / "config/examples";
  const auto before = snapshot(examples);
  const fs::path xdg = dir_.path() / "xdg";
  ASSERT_EQ(setenv("XDG_STATE_HOME", xdg.c_str(), 1), 0);  // the daemon inherits it
  daemon_.use_default_state_dir();
  ASSERT_EQ(start(examples / "sim_mm.ini"), "");
  ready();
  ASSERT_TRUE(mdi("G10 L2 P1 X5").contains("result"));
  ASSERT_TRUE(mdi("G0 X20 Y10").contains("result"));
  EXPECT_EQ(daemon_.stop(), 0);

  const fs::path state = xdg / "cncd/sim_mm";
  EXPECT_EQ(parameter(state / "sim_mm.var", 5221), 5);
  EXPECT_EQ(slurp(state / "sim_mm.tbl"), slurp(examples / "sim_mm.tbl"));  // the seed's copy
  EXPECT_TRUE(fs::exists(state / "sim_mm.position"));
  EXPECT_NE(daemon_.log().find("state files in " + state.string()), std::string::npos)
      << daemon_.log();
  EXPECT_EQ(snapshot(examples), before) << "the example machine's directory was written";

  // The next start goes on from the state, not from the seed.
  daemon_.use_default_state_dir();
  ASSERT_EQ(start(examples / "sim_mm.ini"), "");
  const json g54 = result_of(call("offsets.get"))["systems"][0];
  EXPECT_EQ(g54["name"], "G54");
  EXPECT_EQ(g54["origin"]["x"], 5.0) << g54.dump();
  EXPECT_EQ(daemon_.stop(), 0);
  EXPECT_EQ(parameter(state / "sim_mm.var", 5221), 5);
  EXPECT_EQ(snapshot(examples), before);
}

TEST_F(StateDirDaemonTest, MissingStateFilesStartFromTheDefaultsAndAreCreated) {
  const auto ini = copy_example_machine(dir_.path());
  std::string text = slurp(ini);
  for (const auto& [from, to] :
       std::vector<std::pair<std::string, std::string>>{{"sim_mm.var", "fresh.var"},
                                                        {"sim_mm.tbl", "fresh.tbl"},
                                                        {"sim_mm.position", "fresh.position"}}) {
    text.replace(text.find(" = " + from), from.size() + 3, " = " + to);
  }
  std::ofstream(ini, std::ios::trunc) << text;

  // cncd-check reads the machine without refusing it, and says what is missing.
  const auto program = dir_.write("p.ngc", "G0 X1\nM2\n");
  const auto check = run_command({CNCD_CHECK_BINARY, "--ini", ini.string(), "--state-dir",
                                  dir_.path().string(), program.string()});
  EXPECT_EQ(check.exit_status, 0) << check.err;
  EXPECT_NE(check.err.find("warning: " + (dir_.path() / "fresh.var").string() +
                           ": parameter file does not exist"),
            std::string::npos)
      << check.err;

  ASSERT_EQ(start(ini), "");
  const std::string log = daemon_.log();
  for (const char* name : {"parameter file", "tool table", "position file"}) {
    EXPECT_NE(log.find(std::string(name) + " '"), std::string::npos) << name << "\n" << log;
  }
  EXPECT_NE(log.find("does not exist"), std::string::npos) << log;
  ready();
  const json g10 = mdi("G10 L2 P2 X7");
  ASSERT_TRUE(g10.contains("result")) << g10.dump();
  // Written after the MDI block, as the parameter file always is.
  EXPECT_EQ(parameter(dir_.path() / "fresh.var", 5241), 7);
  EXPECT_EQ(daemon_.stop(), 0);
  EXPECT_TRUE(fs::exists(dir_.path() / "fresh.position"));
  EXPECT_FALSE(fs::exists(dir_.path() / "fresh.var.tmp"));
}

// A link planted where a fixed temporary name would go is never followed: the file it points
// to stays as it was, and the parameter file is written, a regular file, all the same.
TEST_F(StateDirDaemonTest, TheParameterFileIsNeverWrittenThroughALinkBesideIt) {
  const auto ini = copy_example_machine(dir_.path());
  TempDir elsewhere;
  const fs::path victim = elsewhere.write("victim", "precious\n");
  fs::create_symlink(victim, dir_.path() / "sim_mm.var.tmp");
  ASSERT_EQ(start(ini), "");
  ready();
  const json g10 = mdi("G10 L2 P1 X5");
  ASSERT_TRUE(g10.contains("result")) << g10.dump();
  EXPECT_EQ(daemon_.stop(), 0);
  EXPECT_EQ(slurp(victim), "precious\n");
  EXPECT_TRUE(fs::is_symlink(dir_.path() / "sim_mm.var.tmp"));
  EXPECT_FALSE(fs::is_symlink(dir_.path() / "sim_mm.var"));
  EXPECT_EQ(parameter(dir_.path() / "sim_mm.var", 5221), 5);
  // Nor is a temporary file left behind.
  for (const auto& entry : fs::directory_iterator(dir_.path()))
    EXPECT_EQ(entry.path().filename().string().find(".sim_mm.var."), std::string::npos)
        << entry.path();
}

}  // namespace
}  // namespace cncd::test
