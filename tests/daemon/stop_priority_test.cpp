// A stop is served ahead of the work other connections have queued: clients that flood
// status.get batches cannot delay it. The daemon is held with SIGSTOP while the batches and the
// stop are written, so that everything is waiting in its sockets when it resumes; the
// flooders' answers then tell by the state they report which were served before the stop.
#include <signal.h>

#include <memory>

#include "daemon_peer.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr int kFlooders = 8;
constexpr int kBatchesEach = 2;

std::string status_batch() {
  json batch = json::array();
  for (int i = 0; i < 256; ++i)
    batch.push_back({{"jsonrpc", "2.0"}, {"id", i}, {"method", "status.get"}});
  return batch.dump() + "\n";
}

class StopPriorityTest : public MachineTest {
 protected:
  // Queues the flooders' batches, then `stop_line` from a control client that connected after
  // them, resumes the daemon and returns how many of the flooders' status.get answers still
  // saw the machine "off", that is were served before the stop.
  int answers_before_stop(const std::string& stop_line) {
    result_of(call("machine.reset"));
    std::vector<std::unique_ptr<daemon::Client>> flooders;
    for (int i = 0; i < kFlooders; ++i) {
      flooders.push_back(std::make_unique<daemon::Client>());
      EXPECT_EQ(flooders.back()->connect(daemon_.socket()), "");
      EXPECT_EQ(result_of(flooders.back()->call("status.get"))["state"], "off");
    }
    daemon::Client stopper;
    EXPECT_EQ(stopper.connect(daemon_.socket()), "");
    EXPECT_TRUE(stopper.call("status.get").contains("result"));
    const pid_t pid = serving_pid(daemon_.socket());
    EXPECT_GT(pid, 0);
    kill(pid, SIGSTOP);
    EXPECT_TRUE(wait_for_state(pid, 'T'));
    const std::string batch = status_batch();
    for (auto& flooder : flooders) {
      for (int b = 0; b < kBatchesEach; ++b)
        flooder->send_raw(batch);
    }
    stopper.send_raw(stop_line);
    kill(pid, SIGCONT);
    bool stopped = false;
    while (!stopped) {
      const json answer = json::parse(stopper.read_line(30000));
      const json& answers = answer.is_array() ? answer : json::array({answer});
      for (const auto& one : answers) {
        if (one.value("id", json()) == "stop") {
          EXPECT_TRUE(one.contains("result")) << one.dump();
          stopped = true;
        }
      }
    }
    int before = 0;
    for (auto& flooder : flooders) {
      for (int b = 0; b < kBatchesEach;) {
        const json answer = json::parse(flooder->read_line(60000));
        if (!answer.is_array()) continue;  // an event or another notification
        ++b;
        EXPECT_EQ(answer.size(), 256u);
        for (const auto& one : answer)
          before += one["result"]["state"] == "off" ? 1 : 0;
      }
    }
    EXPECT_EQ(status()["state"], "estop");
    return before;
  }
};

TEST_F(StopPriorityTest, AnEstopIsServedBeforeOtherClientsQueuedBatches) {
  EXPECT_EQ(answers_before_stop(R"({"jsonrpc":"2.0","id":"stop","method":"machine.estop"})"
                                "\n"),
            0);
}

TEST_F(StopPriorityTest, AStopInABatchIsServedBeforeOtherClientsQueuedBatches) {
  // The batch is served whole, in its order, ahead of the other connections' work.
  EXPECT_EQ(answers_before_stop(R"([{"jsonrpc":"2.0","id":1,"method":"status.get"},)"
                                R"({"jsonrpc":"2.0","id":"stop","method":"machine.estop"}])"
                                "\n"),
            0);
}

}  // namespace
}  // namespace cncd::test
