// override.feed, override.rapid and override.spindle against the real daemon on the simulated
// mill (config/examples/sim_mm.ini: MAX_FEED_OVERRIDE 1.5, spindle override 0.5 .. 1.2).
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

std::string error_message(const json& response) {
  return response.contains("error") ? response["error"].value("message", "") : "";
}

TEST_F(MachineTest, OverridesAreSetAndShownInStatus) {
  json s = status();
  EXPECT_EQ(s["overrides"], (json{{"feed", 1.0}, {"rapid", 1.0}, {"spindle", 1.0}})) << s.dump();
  EXPECT_EQ(s["spindle"]["override"], 1.0);
  EXPECT_EQ(result_of(call("override.feed", {{"value", 0.5}})), (json{{"value", 0.5}}));
  EXPECT_EQ(result_of(call("override.rapid", {{"value", 0.25}})), (json{{"value", 0.25}}));
  EXPECT_EQ(result_of(call("override.spindle", {{"value", 1.2}})), (json{{"value", 1.2}}));
  // The ends of each range are allowed.
  result_of(call("override.feed", {{"value", 1.5}}));
  result_of(call("override.feed", {{"value", 0}}));
  result_of(call("override.rapid", {{"value", 1}}));
  result_of(call("override.rapid", {{"value", 0.25}}));
  result_of(call("override.feed", {{"value", 0.5}}));
  s = status();
  EXPECT_EQ(s["overrides"], (json{{"feed", 0.5}, {"rapid", 0.25}, {"spindle", 1.2}})) << s.dump();
}

TEST_F(MachineTest, SpindleOverrideScalesTheCommandedSpeed) {
  ready_machine();
  mdi("S1000 M3");
  json s = status();
  EXPECT_EQ(s["spindle"]["speed"], 1000.0) << s.dump();
  result_of(call("override.spindle", {{"value", 0.5}}));
  s = status();
  EXPECT_EQ(s["spindle"]["speed"], 500.0) << s.dump();
  EXPECT_EQ(s["spindle"]["programmed_speed"], 1000.0);
  EXPECT_EQ(s["spindle"]["override"], 0.5);
  EXPECT_EQ(s["spindle"]["direction"], 1);
  EXPECT_EQ(s["overrides"]["spindle"], 0.5);
}

TEST_F(MachineTest, OverridesOutsideTheirRangeAreRefusedNotClamped) {
  struct Case {
    const char* method;
    json params;
    const char* range;
  };
  const std::vector<Case> cases = {
      {"override.feed", {{"value", 1.6}}, "from 0 to 1.5"},
      {"override.feed", {{"value", -0.1}}, "from 0 to 1.5"},
      {"override.feed", {{"value", "0.5"}}, "from 0 to 1.5"},
      {"override.feed", {{"value", true}}, "from 0 to 1.5"},
      {"override.feed", {{"value", nullptr}}, "from 0 to 1.5"},
      {"override.feed", json::object(), "from 0 to 1.5"},
      {"override.feed", nullptr, "from 0 to 1.5"},
      {"override.feed", json::array({0.5}), "from 0 to 1.5"},
      {"override.rapid", {{"value", 1.01}}, "from 0 to 1"},
      {"override.rapid", {{"value", -1}}, "from 0 to 1"},
      {"override.spindle", {{"value", 0.4}}, "from 0.5 to 1.2"},
      {"override.spindle", {{"value", 1.3}}, "from 0.5 to 1.2"},
  };
  for (const auto& c : cases) {
    const json r = call(c.method, c.params);
    EXPECT_EQ(error_code(r), -32602) << c.method << " " << c.params.dump();
    EXPECT_NE(error_message(r).find(c.range), std::string::npos) << r.dump();
  }
  // Nothing changed: a refused value is never clamped into the range.
  EXPECT_EQ(status()["overrides"], (json{{"feed", 1.0}, {"rapid", 1.0}, {"spindle", 1.0}}));
}

TEST_F(MachineTest, HalfFeedOverrideTakesTwiceAsLong) {
  ready_machine();
  // 6 mm at 10 mm/s there and back; accelerating at 2000 mm/s^2 takes a few ms of each move.
  const auto program = dir_.write("feed.ngc", "G21 G90 G1 F600 X6\nX0\nM2\n");
  // The time the program takes at `ratio` on the servo clock (motion_s: wall time would also count
  // the periods a stalled servo thread skipped on a busy machine).
  const auto seconds_at = [&](double ratio) {
    result_of(call("override.feed", {{"value", ratio}}));
    result_of(call("program.open", {{"path", program.string()}}));
    result_of(call("program.run"));
    const json s = wait_until([](const json& st) { return st["exec"] == "idle"; });
    EXPECT_EQ(s["program"]["result"], "done") << s.dump();
    return s["program"]["motion_s"].get<double>();
  };
  const double full = seconds_at(1.0);
  const double half = seconds_at(0.5);
  RecordProperty("full_s", std::to_string(full));
  RecordProperty("half_s", std::to_string(half));
  EXPECT_GT(full, 0.5);
  EXPECT_GT(half / full, 1.7) << "full " << full << " s, half " << half << " s";
  EXPECT_LT(half / full, 2.3) << "full " << full << " s, half " << half << " s";
}

TEST_F(MachineTest, ZeroFeedOverrideHoldsMotionUntilRaised) {
  ready_machine();
  start_program("hold.ngc", "G21 G90 G1 F600 X20\nM2\n");
  wait_until([](const json& st) { return st["position"]["commanded"]["x"].get<double>() > 1.0; });
  result_of(call("override.feed", {{"value", 0}}));
  json s = wait_until([](const json& st) { return st["velocity"].get<double>() == 0.0; });
  const double held_at = s["position"]["commanded"]["x"].get<double>();
  EXPECT_LT(held_at, 19.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  s = status();
  EXPECT_EQ(s["position"]["commanded"]["x"].get<double>(), held_at) << s.dump();
  EXPECT_EQ(s["exec"], "running");
  EXPECT_EQ(s["program"]["result"], "");
  EXPECT_GT(s["distance_to_go"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(s["axes_to_go"]["x"].get<double>(), 20.0 - held_at);
  EXPECT_EQ(s["axes_to_go"]["y"], 0.0);
  result_of(call("override.feed", {{"value", 1.0}}));
  s = wait_until([](const json& st) { return st["exec"] == "idle"; });
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_EQ(s["position"]["commanded"]["x"], 20.0);
  EXPECT_EQ(s["distance_to_go"], 0.0);
  EXPECT_EQ(s["axes_to_go"]["x"], 0.0);
}

TEST_F(MachineTest, RapidOverrideCapsTraverses) {
  ready_machine();
  result_of(call("override.rapid", {{"value", 0.1}}));
  start_program("rapid.ngc", "G21 G90 G0 X30\nM2\n");
  // Sim mill X: 200 mm/s at most; at 10 % no faster than 20 mm/s.
  double fastest = 0;
  const json s = wait_until([&fastest](const json& st) {
    fastest = std::max(fastest, st["velocity"].get<double>());
    return st["exec"] == "idle";
  });
  EXPECT_EQ(s["program"]["result"], "done");
  EXPECT_GT(fastest, 15.0);  // at the capped speed, not slowed by something else
  EXPECT_LE(fastest, 20.0 + 1e-6);
}

}  // namespace
}  // namespace cncd::test
