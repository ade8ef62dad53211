// A real cncd on the simulated mill with a full panel (config/examples/sim_panel_mill.ini, every
// input a sim signal named as its key in lower case): tests press its buttons, flip its switches
// and turn its knobs through sim.set, as an integrator rehearsing a panel does, and judge what
// the machine did by its status and events.
#pragma once

#include <cctype>
#include <string>

#include "machine_fixture.hpp"

namespace cncd::test {

class PanelTest : public MachineTest {
 protected:
  void SetUp() override {
    ini_ = copy_example_machine(dir_.path(), "sim_panel_mill");
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
    // The rapid override's knob turned up: at 0 V it would hold every traverse still.
    ASSERT_NO_FATAL_FAILURE(set("rapid_override_analog", 10));
  }

  void set(const std::string& signal, const nlohmann::json& value) {
    const auto r = call("sim.set", {{"signal", signal}, {"value", value}});
    ASSERT_TRUE(r.contains("result")) << signal << " = " << value.dump() << ": " << r.dump();
  }

  // Sets the input of panel key `key` (its sim signal is the key in lower case) and waits until
  // the servo thread has taken the level (debounced).
  void level(const std::string& key, bool on) {
    std::string signal = key;
    for (char& c : signal)
      c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    ASSERT_NO_FATAL_FAILURE(set(signal, on ? 1 : 0));
    wait_until([&](const nlohmann::json& s) { return s["panel"]["inputs"][key] == on; },
               std::chrono::seconds(10));
  }

  // A press and release of the button `key`.
  void press(const std::string& key) {
    ASSERT_NO_FATAL_FAILURE(level(key, true));
    ASSERT_NO_FATAL_FAILURE(level(key, false));
  }

  std::uint64_t last_seq() { return result_of(call("errors.list"))["last_seq"]; }
  nlohmann::json events_since(std::uint64_t since) {
    return result_of(call("errors.list", {{"since", since}}))["events"];
  }
  // The first event after `since` by the panel whose message starts with `start`; waits for
  // it up to 10 s, null when none came.
  nlohmann::json panel_event(std::uint64_t since, const std::string& start) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
      for (const auto& e : events_since(since)) {
        if (e.value("by", "") == "panel" && e["kind"] == "command" &&
            e["message"].get<std::string>().rfind(start, 0) == 0)
          return e;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return nullptr;
  }

  void open_program(const std::string& name, const std::string& text) {
    const auto program = dir_.write(name, text);
    result_of(call("program.open", {{"path", program.string()}}));
  }

  double commanded(const nlohmann::json& s, const char* axis) {
    return s["position"]["commanded"][axis].get<double>();
  }
};

}  // namespace cncd::test
