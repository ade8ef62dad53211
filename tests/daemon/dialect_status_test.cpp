// status.get's program.dialect: the open program's dialect (its first line, else the
// machine's [RS274NGC] DIALECT), the machine's with no program open, and the program run in it;
// and the DRO under G7 (lathe diameter mode).
#include <string>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// Valid in both dialects, drilled differently: LinuxCNC retracts to R 2 (G99), Numeryx to the
// initial Z 10 (G98).
const std::string kCycle = "g0 x0 y0 z10\nf1200\ng81 r2 z-5\nx5\ng80\nm30\n";

std::string dialect_of(const json& status) {
  return status["program"]["dialect"].get<std::string>();
}

TEST_F(MachineTest, ProgramDialectIsTheFirstLinesElseTheMachines) {
  EXPECT_EQ(dialect_of(status()), "linuxcnc");  // no program open: the machine's
  const auto numeryx = dir_.write("nx.ngc", "(dialect numeryx)\n" + kCycle);
  const auto plain = dir_.write("plain.ngc", kCycle);
  result_of(call("program.open", {{"path", numeryx.string()}}));
  EXPECT_EQ(dialect_of(status()), "numeryx");
  // Only the asked-for fields: program among them.
  const json only = result_of(call("status.get", {{"fields", {"program"}}}));
  EXPECT_EQ(only["program"]["dialect"], "numeryx");
  result_of(call("program.open", {{"path", plain.string()}}));
  EXPECT_EQ(dialect_of(status()), "linuxcnc");

  // Run in its dialect: the Numeryx cycle ends at the initial Z, the LinuxCNC one at R.
  ready_machine();
  result_of(call("program.open", {{"path", numeryx.string()}}));
  result_of(call("program.run"));
  json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s["program"].dump();
  EXPECT_EQ(dialect_of(s), "numeryx");
  EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), 10.0, 1e-9);
  // An MDI block after it leaves the open program's dialect in the status.
  mdi("G0 Z20");
  EXPECT_EQ(dialect_of(status()), "numeryx");
  result_of(call("program.open", {{"path", plain.string()}}));
  result_of(call("program.run"));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s["program"].dump();
  EXPECT_EQ(dialect_of(s), "linuxcnc");
  EXPECT_NEAR(s["position"]["commanded"]["z"].get<double>(), 2.0, 1e-9);
}

// G7 G0 X20 puts the tool at radius 10; the DRO (work_position) shows the diameter 20 and the
// status names the mode; G8 shows the radius again.
TEST_F(MachineTest, UnderG7XGoesToTheRadiusAndTheDroShowsTheDiameter) {
  ready_machine();
  EXPECT_EQ(status()["diameter_mode"], false);
  mdi("G21 G90 G18 G7 G0 X20");
  json s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 20.0, 1e-9);
  EXPECT_EQ(s["diameter_mode"], true);
  EXPECT_NE(s["gcodes"].dump().find("\"G7\""), std::string::npos) << s["gcodes"].dump();
  mdi("G91 G0 X-4");  // 4 of diameter: 2 of radius
  s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 8.0, 1e-9);
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 16.0, 1e-9);
  mdi("G90 G8");
  s = status();
  EXPECT_EQ(s["diameter_mode"], false);
  EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 8.0, 1e-9);
  EXPECT_NE(s["gcodes"].dump().find("\"G8\""), std::string::npos) << s["gcodes"].dump();
}

// A machine whose [RS274NGC] DIALECT is numeryx: programs without a first line naming
// another, and MDI blocks, are read as Numeryx.
class NumeryxMachineTest : public MachineTest {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path());
    std::string text = slurp(ini_);
    const std::string section = "[RS274NGC]\n";
    const auto at = text.find(section);
    ASSERT_NE(at, std::string::npos);
    text.insert(at + section.size(), "DIALECT = numeryx\n");
    ini_ = dir_.write("numeryx_mill.ini", text);
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
};

TEST_F(NumeryxMachineTest, ProgramsAndMdiAreReadAsNumeryx) {
  EXPECT_EQ(dialect_of(status()), "numeryx");
  // "g" without a number is Numeryx positioning, an error in LinuxCNC.
  const auto numeryx = dir_.write("nx.ngc", "g x1 y2 z10\nm30\n");
  result_of(call("program.open", {{"path", numeryx.string()}}));
  EXPECT_EQ(dialect_of(status()), "numeryx");
  const auto linuxcnc = dir_.write("lc.ngc", "(dialect linuxcnc)\n" + kCycle);
  result_of(call("program.open", {{"path", linuxcnc.string()}}));
  EXPECT_EQ(dialect_of(status()), "linuxcnc");
  // Read as LinuxCNC, the Numeryx positioning is refused at its line.
  const auto refused = dir_.write("refused.ngc", "(dialect linuxcnc)\ng x1 y2 z10\nm30\n");
  const json r = call("program.open", {{"path", refused.string()}});
  EXPECT_EQ(error_code(r), 1003) << r.dump();
  EXPECT_NE(r.dump().find("refused.ngc:2"), std::string::npos) << r.dump();
  EXPECT_EQ(dialect_of(status()), "linuxcnc");  // the open program is still lc.ngc

  ready_machine();
  mdi("g x5 y6 z7");
  const json s = status();
  EXPECT_NEAR(s["position"]["commanded"]["x"].get<double>(), 5.0, 1e-9);
  EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), 6.0, 1e-9);
}

}  // namespace
}  // namespace cncd::test
