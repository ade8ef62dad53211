// Hundreds of clients at once against the real daemon: every one is served and sees every
// change, and one that goes away mid-request harms nothing.

#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "client.hpp"
#include "daemon_process.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

TEST(ManyClients, TwoHundredFiftySixSubscribersAllSeeTheChange) {
  TempDir dir;
  DaemonProcess daemon;
  ASSERT_EQ(daemon.start(dir.path(), {"--ini", copy_example_machine(dir.path()).string()}), "");
  constexpr int kClients = 256;
  std::vector<std::unique_ptr<daemon::Client>> clients;
  for (int i = 0; i < kClients; ++i) {
    auto client = std::make_unique<daemon::Client>();
    ASSERT_EQ(client->connect(daemon.socket()), "") << "client " << i;
    const json r = client->call("status.subscribe", {{"interval_ms", 10}, {"fields", {"state"}}});
    ASSERT_TRUE(r.contains("result")) << r.dump();
    clients.push_back(std::move(client));
  }
  daemon::Client commander;
  ASSERT_EQ(commander.connect(daemon.socket()), "");
  ASSERT_TRUE(commander.call("machine.reset").contains("result"));
  for (int i = 0; i < kClients; ++i) {
    for (;;) {
      const json message = json::parse(clients[static_cast<std::size_t>(i)]->read_line(10000));
      if (message.value("method", "") != "status.update") continue;
      if (message["params"]["changed"].value("state", "") == "off") break;
    }
  }
  // Clients that vanish, some in the middle of a request line, leave the daemon serving.
  for (int i = 0; i < kClients; i += 2) {
    if (i % 4 == 0) clients[static_cast<std::size_t>(i)]->send_raw("{\"jsonrpc\":\"2.0\",\"id\":");
    clients[static_cast<std::size_t>(i)].reset();
  }
  EXPECT_EQ(commander.call("status.get")["result"]["state"], "off");
  EXPECT_EQ(daemon.stop(), 0);
}

}  // namespace
}  // namespace cncd::test
