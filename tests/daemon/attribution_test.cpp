// "on_behalf_of": a front end with control access names the person and the address it serves,
// and the event log says who did what; a malformed one is refused and nothing of the request
// is done. (A read-only peer is refused it: permission_test.cpp.)
#include <unistd.h>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

const json kAlice = {{"user", "alice"}, {"address", "192.168.1.20"}, {"via", "web"}};

class AttributionTest : public MachineTest {
 protected:
  // Sends `method` with `params` on behalf of `who` and returns its answer.
  json call_for(const json& who, const std::string& method, const json& params = nullptr) {
    const long id = next_id_++;
    json request = {{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"on_behalf_of", who}};
    if (!params.is_null()) request["params"] = params;
    client_.send_raw(request.dump() + "\n");
    for (;;) {
      const json line = json::parse(client_.read_line(30000));
      if (line.value("id", json()) == id) return line;
    }
  }
  // The events errors.list keeps after `since`.
  json events_since(std::uint64_t since) {
    return result_of(call("errors.list", {{"since", since}}))["events"];
  }
  std::uint64_t last_seq() { return result_of(call("errors.list"))["last_seq"]; }

  // How this test process is named as the peer.
  const std::string peer_ = "uid " + std::to_string(getuid()) + " pid " + std::to_string(getpid());
  long next_id_ = 1'000'000;
};

TEST_F(AttributionTest, AnAttributedCommandIsRecordedWithThePersonAndAddress) {
  daemon::Client watcher;
  ASSERT_EQ(watcher.connect(daemon_.socket()), "");
  result_of(watcher.call("system.info"));  // connected before the command
  const auto since = last_seq();
  result_of(call_for(kAlice, "machine.reset"));
  result_of(call_for(kAlice, "machine.on"));
  const std::string who = "alice@192.168.1.20 (web) via " + peer_;
  const json events = events_since(since);
  ASSERT_EQ(events.size(), 2u) << events.dump();
  EXPECT_EQ(events[0]["message"], "machine.reset by " + who);
  EXPECT_EQ(events[1]["message"], "machine.on by " + who);
  EXPECT_EQ(events[1]["kind"], "command");
  EXPECT_EQ(events[1]["level"], "info");
  EXPECT_EQ(events[1].value("by", ""), who);
  // Every client is told, as of any event.
  json notice;
  for (int i = 0; i < 10 && notice.is_null(); ++i) {
    const json line = json::parse(watcher.read_line(10000));
    if (line.value("method", "") == "event" && line["params"]["message"] == "machine.on by " + who)
      notice = line["params"];
  }
  EXPECT_EQ(notice["by"], who);
}

TEST_F(AttributionTest, WhatTheRequestCausesNamesThePersonAndARefusalIsRecordedToo) {
  const auto since = last_seq();
  result_of(call_for(kAlice, "tool.set", {{"number", 3}, {"diameter", 6}}));
  const std::string who = "alice@192.168.1.20 (web) via " + peer_;
  json events = events_since(since);
  ASSERT_EQ(events.size(), 2u) << events.dump();
  EXPECT_EQ(events[0]["message"], "tool 3 changed");
  EXPECT_EQ(events[0].value("by", ""), who);
  EXPECT_EQ(events[1]["message"], R"(tool.set {"diameter":6,"number":3} by )" + who);
  // In estop: refused, and recorded as refused.
  const auto before = last_seq();
  EXPECT_EQ(error_code(call_for(kAlice, "machine.on")), 1001);
  events = events_since(before);
  ASSERT_EQ(events.size(), 1u) << events.dump();
  EXPECT_EQ(events[0]["message"],
            "machine.on by " + who + ": refused: machine is in estop: reset it first");
}

TEST_F(AttributionTest, WithoutItCommandsAreNotRecordedButTheirEventsNameThePeer) {
  const auto since = last_seq();
  result_of(call("machine.reset"));
  result_of(call("tool.set", {{"number", 2}, {"diameter", 4}}));
  // A query on behalf of someone is accepted and changes nothing to record.
  EXPECT_TRUE(call_for(kAlice, "status.get").contains("result"));
  const json events = events_since(since);
  ASSERT_EQ(events.size(), 1u) << events.dump();
  EXPECT_EQ(events[0]["message"], "tool 2 changed");
  EXPECT_EQ(events[0].value("by", ""), peer_);
}

TEST_F(AttributionTest, AMalformedOneIsRefusedAndNothingIsDone) {
  const std::string long_name(65, 'a');
  const std::vector<std::pair<json, std::string>> bad = {
      {"alice", "\"on_behalf_of\" must be an object"},
      {{{"user", "alice"}, {"address", "10.0.0.1"}}, "\"on_behalf_of\" lacks \"via\""},
      {{{"user", "alice"}, {"address", "10.0.0.1"}, {"via", "web"}, {"role", "admin"}},
       "unknown member \"role\""},
      {{{"user", "alice via uid 0"}, {"address", "10.0.0.1"}, {"via", "web"}},
       "member \"user\" must be a string of 1 to 64 printable characters without spaces"},
      {{{"user", long_name}, {"address", "10.0.0.1"}, {"via", "web"}}, "member \"user\""},
      {{{"user", "alice"}, {"address", ""}, {"via", "web"}}, "member \"address\""},
      {{{"user", "alice"}, {"address", "10.0.0.1"}, {"via", 7}}, "member \"via\""},
      {{{"user", "al\nice"}, {"address", "10.0.0.1"}, {"via", "web"}}, "member \"user\""},
  };
  const auto since = last_seq();
  for (const auto& [who, why] : bad) {
    const json reply = call_for(who, "machine.reset");
    ASSERT_EQ(error_code(reply), -32600) << who.dump();
    EXPECT_NE(reply["error"]["message"].get<std::string>().find(why), std::string::npos)
        << reply.dump();
  }
  EXPECT_EQ(status()["state"], "estop");
  EXPECT_TRUE(events_since(since).empty());
}

}  // namespace
}  // namespace cncd::test
