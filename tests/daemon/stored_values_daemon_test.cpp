// With the real daemon: no absurd or non-finite value reaches motion or the state files, and
// the state files are recognised before they are used or written. A refused MDI block or
// program names its line; the daemon runs on and starts again normally.
#include <signal.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The largest magnitude of any value in a "NUMBER VALUE" parameter file, and #5221.
struct VarSummary {
  double largest = 0;
  double g54_x = 0;
};
VarSummary summarise(const fs::path& path) {
  VarSummary out;
  std::istringstream lines(slurp(path));
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream in(line);
    int number = 0;
    std::string value;
    EXPECT_TRUE(static_cast<bool>(in >> number >> value)) << line;
    const double v = std::strtod(value.c_str(), nullptr);
    EXPECT_TRUE(std::isfinite(v)) << line;
    out.largest = std::max(out.largest, std::fabs(v));
    if (number == 5221) out.g54_x = v;
  }
  return out;
}

class StoredValuesDaemonTest : public MachineTest {
 protected:
  // The error message of an MDI block that must be refused.
  std::string mdi_refused(const std::string& line) {
    const json r = call("mdi.execute", {{"line", line}});
    EXPECT_TRUE(r.contains("error")) << line << ": " << r.dump();
    return r.contains("error") ? r["error"].value("message", "") : "";
  }
  fs::path parameter_file() const { return dir_.path() / "sim_mm.var"; }
};

TEST_F(StoredValuesDaemonTest, AHugeOffsetFromMdiIsRefusedAtItsLineAndTheDaemonStartsAgain) {
  ready_machine();
  for (const char* line : {"#5221=[10**299*10]", "G10 L2 P1 X[10**299*10]", "G92 X[10**299*10]",
                           "G10 L2 P1 X[1/0]", "G10 L1 P1 Z[-10**10]", "G43.1 Z[10**10]"}) {
    SCOPED_TRACE(line);
    const std::string message = mdi_refused(line);
    EXPECT_NE(message.find("MDI:1:"), std::string::npos) << message;
  }
  EXPECT_NE(mdi_refused("#5221=[10**299*10]").find("Parameter #5221 = 1e+300 is out of range"),
            std::string::npos);
  // Nothing was stored: G0 X1 goes to machine X1.
  mdi("G0 X1");
  json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["fault"], "") << s.dump();
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 1.0, 1e-9) << s.dump();
  EXPECT_EQ(daemon_.stop(), 0);
  const VarSummary saved = summarise(parameter_file());
  EXPECT_LE(saved.largest, 1e9);
  EXPECT_EQ(saved.g54_x, 0.0);
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  ASSERT_EQ(client_.connect(daemon_.socket()), "");
  EXPECT_EQ(status()["fault"], "");
}

TEST_F(StoredValuesDaemonTest, AMoveBeyondTheSoftLimitsFromMdiNamesMdiAndItsLine) {
  ready_machine();
  mdi("G10 L2 P1 X1000000");  // allowed as an origin, but the machine cannot go there
  const std::string message = mdi_refused("G0 X1");
  EXPECT_NE(message.find("MDI:1: move to X 1000001.0000 is outside the X soft limits"),
            std::string::npos)
      << message;
  const json s = status();
  EXPECT_EQ(s["fault"], "") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"].get<double>(), 0.0) << s.dump();
}

TEST_F(StoredValuesDaemonTest, AProgramStoringAHugeOffsetIsRefusedAtOpenAtThatLine) {
  ready_machine();
  for (const char* text :
       {"G0 X1\nG92 X[10**299*10]\nG0 X1\nM2\n", "G0 X1\n#5221=[10**299*10]\nG0 X1\nM2\n",
        "G0 X1\nG10 L2 P1 X[10**12]\nG0 X1\nM2\n"}) {
    SCOPED_TRACE(text);
    const auto program = dir_.write("huge.ngc", text);
    const json r = call("program.open", {{"path", program.string()}});
    EXPECT_EQ(error_code(r), 1003);
    const std::string message = r.contains("error") ? r["error"].value("message", "") : "";
    EXPECT_NE(message.find(program.string() + ":2:"), std::string::npos) << message;
    EXPECT_NE(message.find("out of range"), std::string::npos) << message;
  }
}

// PARAMETER_FILE mistyped to name a file that is not a parameter file: the daemon refuses to
// start, names the file and line, and never writes over it; cncd-check neither.
class ForeignParameterFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path());
    std::string text = slurp(ini_);
    const std::string from = "PARAMETER_FILE = sim_mm.var";
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos);
    foreign_ = dir_.path() / "passwd";
    text.replace(at, from.size(), "PARAMETER_FILE = " + foreign_.string());
    std::ofstream(ini_, std::ios::binary) << text;
  }
  TempDir dir_;
  fs::path ini_;
  fs::path foreign_;
  DaemonProcess daemon_;
};

TEST_F(ForeignParameterFileTest, APasswdFileIsRefusedAtStartAndLeftAlone) {
  const std::string passwd =
      "root:x:0:0:root:/root:/bin/bash\n"
      "daemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin\n"
      "5221:x:5221:5221::/home/machinist:/bin/sh\n";
  std::ofstream(foreign_, std::ios::binary) << passwd;
  const std::string error = daemon_.start(dir_.path(), {"--ini", ini_.string()});
  EXPECT_NE(error.find("status 78"), std::string::npos) << error;
  EXPECT_NE(error.find(foreign_.string() + ":1: 'root:x:0:0:root:/root:/bin/bash' is not a "
                                           "parameter line"),
            std::string::npos)
      << error;
  EXPECT_EQ(slurp(foreign_), passwd);

  const auto program = dir_.write("prog.ngc", "G0 X1\nM2\n");
  const auto check = run_command({CNCD_CHECK_BINARY, "--ini", ini_.string(), "--state-dir",
                                  dir_.path().string(), program.string()});
  EXPECT_NE(check.exit_status, 0);
  EXPECT_NE(check.err.find(foreign_.string() + ":1:"), std::string::npos) << check.err;
  EXPECT_EQ(check.err.find(foreign_.string() + ": " + foreign_.string()), std::string::npos)
      << check.err;
  EXPECT_EQ(slurp(foreign_), passwd);
  for (const auto& entry : fs::directory_iterator(dir_.path()))
    EXPECT_EQ(entry.path().filename().string().find(".passwd"), std::string::npos)
        << "temporary file left: " << entry.path();
}

TEST_F(ForeignParameterFileTest, TheToolTableOrTheIniAsParameterFileIsRefusedToo) {
  for (const std::string& text : {slurp(dir_.path() / "sim_mm.tbl"), slurp(ini_)}) {
    std::ofstream(foreign_, std::ios::binary) << text;
    const std::string error = daemon_.start(dir_.path(), {"--ini", ini_.string()});
    EXPECT_NE(error.find("status 78"), std::string::npos) << error;
    EXPECT_NE(error.find(foreign_.string() + ":"), std::string::npos) << error;
    EXPECT_EQ(slurp(foreign_), text);
  }
}

class PositionFileTest : public ::testing::Test {
 protected:
  void SetUp() override { ini_ = copy_example_machine(dir_.path()); }
  std::string start() { return daemon_.start(dir_.path(), {"--ini", ini_.string()}); }
  fs::path position_file() const { return dir_.path() / "sim_mm.position"; }
  TempDir dir_;
  fs::path ini_;
  DaemonProcess daemon_;
};

TEST_F(PositionFileTest, ValuesThatAreNotFiniteAreRefusedWithFileLineAndValue) {
  for (const char* bad : {"nan", "inf", "-inf", "1e400"}) {
    SCOPED_TRACE(bad);
    const std::string text = std::string("1.0\n") + bad + "\n3.0\n";
    std::ofstream(position_file()) << text;
    const std::string error = start();
    EXPECT_NE(error.find("status 78"), std::string::npos) << error;
    EXPECT_NE(error.find("sim_mm.position:2: '" + std::string(bad) + "'"), std::string::npos)
        << error;
    EXPECT_EQ(slurp(position_file()), text);
  }
}

TEST_F(PositionFileTest, PositionsFarOutsideTheJointLimitsAreRefusedWithTheLimits) {
  // Joint 0 travels -10 .. 300: 10 % of that (31) beyond a limit is still accepted.
  const std::string far = "0\n0\n-300\n";
  std::ofstream(position_file()) << far;
  const std::string error = start();
  EXPECT_NE(error.find("status 78"), std::string::npos) << error;
  EXPECT_NE(error.find("sim_mm.position:3: joint 2 position -300 is outside its limits "
                       "[-100, 50] by more than 10 % of its travel"),
            std::string::npos)
      << error;
  EXPECT_EQ(slurp(position_file()), far);

  std::ofstream(position_file()) << "330\n-30\n0\n";
  ASSERT_EQ(start(), "");
  EXPECT_EQ(daemon_.stop(), 0);
}

}  // namespace
}  // namespace cncd::test
