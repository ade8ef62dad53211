// cncd-fleet against a real mosquitto broker: machines' retained states fill its table and
// reach a browser's WebSocket; malformed, oversized and odd input, and thousands of machines,
// neither crash it nor break the table.
#include "fleet_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

json state(const std::string& machine, const std::string& st, const std::string& exec,
           double progress) {
  return {{"machine", machine},
          {"cncd", "connected"},
          {"state", st},
          {"mode", "auto"},
          {"exec", exec},
          {"program",
           {{"path", "/srv/ngc/bracket.ngc"},
            {"line", 12},
            {"progress", progress},
            {"remaining_s", 75.5},
            {"estimated_s", 120}}},
          {"parts", 41},
          {"dashboard", "http://" + machine + ".shop:8080/"},
          {"last_error", nullptr},
          {"time", 1795913692.4}};
}

TEST_F(FleetTest, RetainedStatesFillTheTableAndChangesReachTheWebSocket) {
  Publisher pub(broker_.port());
  pub.publish("cncd/mill-1/state", state("mill-1", "on", "running", 0.25).dump());
  pub.publish("cncd/mill-1/availability", "online");
  ASSERT_TRUE(pub.flushed());
  start_fleet();  // after the publish: what it shows came retained
  const json row = row_when("cncd/mill-1", [](const json& r) { return r["online"] == "online"; });
  ASSERT_TRUE(row.is_object());
  EXPECT_EQ(row["name"], "mill-1");
  EXPECT_EQ(row["state"], "on");
  EXPECT_EQ(row["exec"], "running");
  EXPECT_EQ(row["program"], "/srv/ngc/bracket.ngc");
  EXPECT_EQ(row["progress"], 0.25);
  EXPECT_EQ(row["remaining_s"], 75.5);
  EXPECT_EQ(row["parts"], 41);
  EXPECT_EQ(row["dashboard"], "http://mill-1.shop:8080/");

  WsReader ws(port_);
  ASSERT_FALSE(ws.error()) << ws.error().message();
  const json snapshot = ws.next();
  ASSERT_EQ(snapshot["type"], "snapshot") << snapshot.dump();
  EXPECT_EQ(snapshot["broker"]["connected"], true);
  ASSERT_EQ(snapshot["machines"].size(), 1u);
  EXPECT_EQ(snapshot["machines"][0]["exec"], "running");

  // An estop, its alarm event, then the machine's telemetry gone: each reaches the page.
  pub.publish("cncd/mill-1/state", state("mill-1", "estop", "idle", 0.5).dump());
  pub.publish("cncd/mill-1/events",
              json{{"seq", 9},
                   {"time", 1795913700.0},
                   {"level", "error"},
                   {"kind", "estop"},
                   {"message", "emergency stop pressed"}}
                  .dump(),
              false);
  pub.publish("cncd/mill-1/availability", "offline");
  ASSERT_TRUE(pub.flushed());
  json seen = snapshot["machines"][0];
  for (int frames = 0; frames < 50; ++frames) {
    if (seen["state"] == "estop" && seen["online"] == "offline" && seen["alarm"].is_object()) break;
    const json frame = ws.next();
    ASSERT_TRUE(frame.is_object()) << "no frame; log:\n" << fleet_->err_so_far();
    if (frame["type"] != "update") continue;
    for (const auto& m : frame["machines"])
      if (m["id"] == "cncd/mill-1") seen = m;
  }
  EXPECT_EQ(seen["state"], "estop");
  EXPECT_EQ(seen["online"], "offline");
  EXPECT_EQ(seen["alarm"]["message"], "emergency stop pressed");
  EXPECT_EQ(seen["alarm"]["seq"], 9);

  // An older event sent again (QoS 1 may repeat) does not replace the newer alarm; the state
  // after it (messages of one publisher keep their order) shows it was taken in.
  pub.publish("cncd/mill-1/events", json{{"seq", 3}, {"level", "error"}, {"message", "old"}}.dump(),
              false);
  json later = state("mill-1", "estop", "idle", 0.5);
  later["parts"] = 42;
  pub.publish("cncd/mill-1/state", later.dump());
  ASSERT_TRUE(pub.flushed());
  const json after = row_when("cncd/mill-1", [](const json& r) { return r["parts"] == 42; });
  EXPECT_EQ(after["alarm"]["message"], "emergency stop pressed");
  // A cleared retained state and availability remove the machine.
  pub.publish("cncd/mill-1/state", "");
  pub.publish("cncd/mill-1/availability", "");
  for (int i = 0; i < 3000 && !machines().empty(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_TRUE(machines().empty()) << machines().dump();
}

TEST_F(FleetTest, BadInputIsIgnoredLoggedAndBreaksNothing) {
  start_fleet();  // the default limit, 64 KiB
  Publisher pub(broker_.port());
  pub.publish("cncd/m1/state", "{\"machine\": \"m1\", \"state\":");  // cut short
  pub.publish("cncd/m2/state", "[1, 2, 3]");
  pub.publish("cncd/m3/state", std::string(1 << 20, 'x'));
  std::string deep;  // 10000 levels of objects, under the size limit
  for (int i = 0; i < 10000; ++i)
    deep += "{\"a\":";
  pub.publish("cncd/m4/state", deep + "1" + std::string(10000, '}'));
  pub.publish("cncd/m5/availability", "maybe");
  pub.publish("cncd/m6/state", "{\"machine\": \"bad \xff\xfe utf-8\"}");
  pub.publish("cncd/too/deep/state", state("deep", "on", "idle", 0).dump());
  // Wrong types and odd values: kept as null, never thrown on.
  pub.publish("cncd/m7/state", json{{"machine", 42},
                                    {"state", json::array({1})},
                                    {"program", "not an object"},
                                    {"parts", "many"},
                                    {"dashboard", "javascript:alert(1)"},
                                    {"last_error", {{"message", 5}}}}
                                   .dump());
  // Odd characters in topic levels and names reach the table as text.
  const std::string odd = "<img src=x onerror=alert(1)> \"quoted\" \xc3\xa9";
  pub.publish("cncd/" + odd + "/state", state(odd, "on", "idle", 0).dump());
  pub.publish("cncd/good/state", state("good", "on", "idle", 0).dump());
  ASSERT_TRUE(pub.flushed());
  const json good = row_when("cncd/good", [](const json&) { return true; });
  EXPECT_EQ(good["state"], "on");
  const json odd_row = row_when("cncd/" + odd, [](const json&) { return true; });
  EXPECT_EQ(odd_row["name"], odd);
  const json m7 = row_when("cncd/m7", [](const json&) { return true; });
  EXPECT_EQ(m7["name"], "cncd/m7");  // a name that is not text: the topic's
  EXPECT_TRUE(m7["state"].is_null());
  EXPECT_TRUE(m7["program"].is_null());
  EXPECT_TRUE(m7["parts"].is_null());
  EXPECT_TRUE(m7["dashboard"].is_null());
  // Deep but whole JSON is an object like any other, with nothing the page shows.
  EXPECT_TRUE(row_when("cncd/m4", [](const json&) { return true; })["state"].is_null());
  for (const auto& row : machines()) {
    for (const char* bad : {"cncd/m1", "cncd/m2", "cncd/m3", "cncd/m5", "cncd/m6"})
      EXPECT_NE(row["id"], bad) << row.dump();
    EXPECT_NE(row["id"], "cncd/too/deep");
  }
  EXPECT_TRUE(alive());
  const std::string log = fleet_->err_so_far();
  EXPECT_NE(log.find("ignored a message on cncd/m1/state: payload not JSON"), std::string::npos)
      << log;
  EXPECT_NE(log.find("ignored a message on cncd/m3/state: payload over the size limit"),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("cncd/m2/state: payload not as expected"), std::string::npos) << log;
  EXPECT_NE(log.find("cncd/m5/availability: payload not as expected"), std::string::npos) << log;
  // The WebSocket's frames are valid JSON with the odd name intact.
  WsReader ws(port_);
  const json snapshot = ws.next();
  ASSERT_EQ(snapshot["type"], "snapshot");
  bool found = false;
  for (const auto& m : snapshot["machines"])
    found |= m["name"] == odd;
  EXPECT_TRUE(found) << snapshot.dump();
}

TEST_F(FleetTest, ThousandsOfMachinesStopAtTheTablesLimit) {
  start_fleet({"--max-machines", "1000"});
  Publisher pub(broker_.port());
  for (int i = 0; i < 3000; ++i)
    pub.publish("cncd/m" + std::to_string(i) + "/state",
                state("m" + std::to_string(i), "on", "idle", 0).dump(), true, i % 10 == 0 ? 1 : 0);
  ASSERT_TRUE(pub.flushed());
  std::size_t count = 0;
  for (int i = 0; i < 3000 && count < 1000; ++i) {
    count = machines().size();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(machines().size(), 1000u);
  EXPECT_NE(fleet_->err_so_far().find("machine beyond the table's limit: already 1000 machines"),
            std::string::npos);
  // The machines in the table still change.
  const std::string first = machines()[0]["id"];
  pub.publish(first + "/state", state("x", "estop", "idle", 0).dump());
  ASSERT_TRUE(pub.flushed());
  EXPECT_TRUE(row_when(first, [](const json& r) { return r["state"] == "estop"; }).is_object());
  EXPECT_TRUE(alive());
}

TEST_F(FleetTest, AWebSocketFromAnotherSiteIsRefused) {
  start_fleet();
  WsReader other(port_, "http://evil.example");
  EXPECT_TRUE(other.error());
  EXPECT_EQ(other.status(), 403);
  WsReader own(port_, "http://127.0.0.1:" + std::to_string(port_));
  EXPECT_FALSE(own.error()) << own.error().message();
  EXPECT_EQ(own.next()["type"], "snapshot");
}

TEST_F(FleetTest, BadOptionsAreRefusedNamingWhatIsWrong) {
  const auto run = [](std::vector<std::string> args) {
    args.insert(args.begin(), CNCD_FLEET_BINARY);
    BackgroundCommand fleet(args);
    return fleet.wait();
  };
  auto r = run({"--topics", "cncd/#"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("'cncd/#' is not a topic pattern"), std::string::npos) << r.err;
  r = run({"--listen", "localhost"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("'localhost' is not ADDRESS:PORT"), std::string::npos) << r.err;
  r = run({"--max-machines", "0"});
  EXPECT_EQ(r.exit_status, 2);
  EXPECT_NE(r.err.find("'0' is not a valid value for --max-machines"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace cncd::test
