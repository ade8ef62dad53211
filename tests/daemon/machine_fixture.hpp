// A real cncd on the simulated mill, in a temporary directory of its own, with a connected
// client and helpers to bring the machine up and wait on its status.
#pragma once

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "client.hpp"
#include "client_checks.hpp"
#include "daemon_process.hpp"

namespace cncd::test {

inline nlohmann::json result_of(const nlohmann::json& response) {
  EXPECT_TRUE(response.contains("result")) << response.dump();
  return response.value("result", nlohmann::json());
}

inline int error_code(const nlohmann::json& response) {
  EXPECT_TRUE(response.contains("error")) << response.dump();
  return response.contains("error") ? response["error"].value("code", 0) : 0;
}

// Every method cncd serves, written out rather than taken from the method table: a method
// served without a table entry, or an entry without its method here, fails
// RpcParams.TableListsEveryServedMethod.
inline const std::vector<std::string>& served_methods() {
  static const std::vector<std::string> methods = {
      "status.get",    "status.subscribe", "status.unsubscribe", "errors.list",     "system.info",
      "machine.estop", "machine.reset",    "machine.on",         "machine.off",     "machine.home",
      "jog.start",     "jog.stop",         "jog.increment",      "program.open",    "program.run",
      "program.step",  "program.pause",    "program.resume",     "program.abort",   "mdi.execute",
      "override.feed", "override.rapid",   "override.spindle",   "tool.list",       "tool.set",
      "offsets.get",   "offsets.set",      "tool.change_done",   "program.preview", "jog.heartbeat",
      "wait.done",     "sim.set",          "jobs.history",       "jobs.stats"};
  return methods;
}

// cncctl with `args`, talking to the daemon at `socket`.
inline CommandResult run_cncctl(const std::string& socket, const std::vector<std::string>& args) {
  std::vector<std::string> argv{CNCCTL_BINARY, "--socket", socket};
  argv.insert(argv.end(), args.begin(), args.end());
  return run_command(argv);
}

class MachineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path(), example());
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  // The example machine (config/examples/NAME.ini) the daemon runs.
  virtual std::string example() const { return "sim_mm"; }

  nlohmann::json call(const std::string& method, const nlohmann::json& params = nullptr) {
    return client_.call(method, params, 30000);
  }
  nlohmann::json status() { return result_of(call("status.get")); }
  // Writes `text` to `name` in the test's directory, opens it and starts it with `method`
  // (program.run or program.step).
  void start_program(const std::string& name, const std::string& text,
                     const char* method = "program.run") {
    const auto program = dir_.write(name, text);
    result_of(call("program.open", {{"path", program.string()}}));
    result_of(call(method));
  }
  CommandResult cncctl(const std::vector<std::string>& args) {
    return run_cncctl(daemon_.socket(), args);
  }

  // Out of estop, on and homed.
  void ready_machine() {
    result_of(call("machine.reset"));
    result_of(call("machine.on"));
    result_of(call("machine.home"));
    wait_until([](const nlohmann::json& s) {
      for (const auto& h : s["homed"]) {
        if (!h.get<bool>()) return false;
      }
      return s["motion"] == "idle";
    });
  }

  void mdi(const std::string& line) {
    const auto r = call("mdi.execute", {{"line", line}});
    ASSERT_TRUE(r.contains("result")) << line << ": " << r.dump();
  }

  template <typename Predicate>
  nlohmann::json wait_until(Predicate done, std::chrono::seconds limit = std::chrono::seconds(60)) {
    return poll_status([this] { return status(); }, done, limit);
  }

  TempDir dir_;
  std::filesystem::path ini_;
  DaemonProcess daemon_;
  daemon::Client client_;
};

}  // namespace cncd::test
