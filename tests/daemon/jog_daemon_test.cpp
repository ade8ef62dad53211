// jog.start, jog.stop and jog.increment through the real daemon and cncctl.
#include <thread>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

class JogTest : public MachineTest {
 protected:
  double x() { return status()["position"]["commanded"]["x"].get<double>(); }
};

TEST_F(JogTest, ContinuousJogRunsUntilStoppedAndStopsUnderControl) {
  ready_machine();
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 20}}));
  EXPECT_EQ(status()["motion"], "jogging");
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const double moving = x();
  EXPECT_GT(moving, 1);
  // No program while jogging; no second jog on the same axis by increment.
  EXPECT_EQ(error_code(call("mdi.execute", {{"line", "G0 Y10"}})), 1004);
  EXPECT_EQ(error_code(call("jog.increment", {{"axis", "X"}, {"distance", 1}})), 1004);
  result_of(call("jog.stop", {{"axis", "X"}}));
  const auto s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_GT(s["position"]["commanded"]["x"].get<double>(), moving);
  EXPECT_EQ(s["fault"], "");
  EXPECT_EQ(s["position"]["commanded"]["y"].get<double>(), 0);
}

TEST_F(JogTest, IncrementsAndSoftLimitsThroughCncctl) {
  ready_machine();
  auto r = cncctl({"jog", "Y", "--increment", "12.5", "--velocity", "50"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_NE(r.out.find("Y 12.5000"), std::string::npos) << r.out;
  // Z's maximum soft limit is 50: a long jog ends there exactly, and no further.
  r = cncctl({"jog", "Z", "+100"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  const auto s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_EQ(s["position"]["commanded"]["z"].get<double>(), 50.0);
  r = cncctl({"jog", "Z", "+1"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("maximum soft limit"), std::string::npos) << r.err;
  r = cncctl({"jog", "Z", "-5"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  r = cncctl({"jog", "Z", "stop"});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  EXPECT_LT(status()["position"]["commanded"]["z"].get<double>(), 50.0);
  EXPECT_EQ(cncctl({"jog", "Q", "+1"}).exit_status, 2);
  EXPECT_EQ(cncctl({"jog", "X"}).exit_status, 64);
}

TEST_F(JogTest, RefusedWhenOffAndStoppedByEstop) {
  EXPECT_EQ(error_code(call("jog.start", {{"axis", "X"}, {"velocity", 10}})), 1001);
  EXPECT_EQ(error_code(call("jog.start", {{"axis", "X"}})), -32602);
  ready_machine();
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", -5}}));
  result_of(call("machine.estop"));
  const auto s = status();
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_EQ(s["state"], "estop");
}

// One hand on the machine: while one client jogs, another's jog is refused naming it (its
// stop is not), the jogging client may jog a second axis, and status says who holds it.
TEST_F(JogTest, AnotherClientsJogIsRefusedNamingTheOneThatJogs) {
  ready_machine();
  EXPECT_TRUE(status()["manual_holder"].is_null());
  result_of(call("jog.start", {{"axis", "X"}, {"velocity", 2}}));
  json s = status();
  ASSERT_TRUE(s["manual_holder"].is_object()) << s["manual_holder"].dump();
  const std::string holder = s["manual_holder"]["by"];
  EXPECT_NE(holder.find(" pid "), std::string::npos) << holder;
  EXPECT_EQ(s["manual_holder"]["panel"], false);
  EXPECT_EQ(s["manual_holder"]["axis"], "X");

  // cncctl is another client (another process).
  auto r = cncctl({"jog", "Y", "-5"});
  EXPECT_NE(r.exit_status, 0);
  EXPECT_NE(r.err.find(holder + " is jogging X: wait until the jog stops"), std::string::npos)
      << r.err;
  // The one that jogs may jog another axis too; then nobody is named for one axis.
  result_of(call("jog.start", {{"axis", "Y"}, {"velocity", -2}}));
  s = status();
  EXPECT_EQ(s["manual_holder"]["by"], holder);
  EXPECT_TRUE(s["manual_holder"]["axis"].is_null());
  // Anyone stops a jog (cncctl waits until the machine rests).
  result_of(call("jog.stop", {{"axis", "X"}}));
  EXPECT_EQ(cncctl({"jog", "Y", "stop"}).exit_status, 0);
  s = wait_until([](const json& st) { return st["motion"] == "idle"; });
  EXPECT_TRUE(s["manual_holder"].is_null());
  // At rest, the other client jogs.
  const double y = s["position"]["commanded"]["y"];
  r = cncctl({"jog", "Y", "--increment", "-1"});
  ASSERT_EQ(r.exit_status, 0) << r.err;
  s = wait_until([y](const json& st) {
    return st["motion"] == "idle" && st["position"]["commanded"]["y"].get<double>() < y;
  });
  EXPECT_NEAR(s["position"]["commanded"]["y"].get<double>(), y - 1, 1e-9);
}

}  // namespace
}  // namespace cncd::test
