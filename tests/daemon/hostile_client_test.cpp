// Every method with parameters of every wrong shape, odd ids and pathological JSON: each gets a
// JSON-RPC answer and the daemon stays up and consistent.
#include <algorithm>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

// Every served method but machine.reset and machine.on, which would bring the machine up.
std::vector<std::string> methods() {
  std::vector<std::string> methods = served_methods();
  std::erase(methods, "machine.reset");
  std::erase(methods, "machine.on");
  return methods;
}

std::vector<json> odd_values() {
  return {nullptr,
          true,
          0,
          -1,
          1.5,
          1e308,
          -1e308,
          json(std::uint64_t{18446744073709551615ULL}),
          json(std::int64_t{4294967296LL}),
          json(std::int64_t{-9223372036854775807LL - 1}),
          "",
          "X",
          std::string(10000, 'Z'),
          json::array(),
          json::array({1, "a", nullptr}),
          json::object(),
          json{{"x", {{"y", {{"z", 1}}}}}}};
}

// Objects with every parameter name the methods use, each set to each odd value.
std::vector<json> odd_params() {
  std::vector<json> out = {nullptr, json::array(), json::array({1, 2}), json::object()};
  for (const char* name : {"value", "fields", "interval_ms", "since", "joints", "axis", "velocity",
                           "distance", "line", "path", "from_line", "number", "pocket", "offset",
                           "diameter", "comment", "system", "origin", "rotation"}) {
    for (const auto& value : odd_values())
      out.push_back(json{{name, value}});
  }
  return out;
}

TEST_F(MachineTest, OddParamsToEveryMethodGetAnAnswer) {
  // The machine stays in estop: nothing may move whatever the parameters say. One batch a
  // method keeps this quick; mdi.execute and program.abort, which answer later outside a
  // batch, are also sent one by one with every third set of parameters.
  const auto params = odd_params();
  const auto answer_to = [&](const json& request) {
    client_.send_raw(request.dump() + "\n");
    json answer;
    do {  // past notifications (events, updates of a subscription just made)
      answer = json::parse(client_.read_line(10000), nullptr, false);
    } while (answer.is_object() && answer.contains("method"));
    return answer;
  };
  const auto request = [](const std::string& method, const json& p, int id) {
    json r = {{"jsonrpc", "2.0"}, {"id", id}, {"method", method}};
    if (!p.is_null()) r["params"] = p;
    return r;
  };
  constexpr std::size_t kBatch = 200;  // within the 256 a batch may hold
  for (const auto& method : methods()) {
    for (std::size_t first = 0; first < params.size(); first += kBatch) {
      json batch = json::array();
      for (std::size_t i = first; i < std::min(params.size(), first + kBatch); ++i)
        batch.push_back(request(method, params[i], static_cast<int>(i)));
      const json answers = answer_to(batch);
      ASSERT_TRUE(answers.is_array()) << method << ": " << answers.dump().substr(0, 300);
      ASSERT_EQ(answers.size(), batch.size()) << method;
      for (std::size_t k = 0; k < answers.size(); ++k) {
        const std::size_t i = first + k;
        EXPECT_EQ(answers[k]["id"], i) << method;
        EXPECT_TRUE(answers[k].contains("result") != answers[k].contains("error"))
            << method << " " << params[i].dump().substr(0, 100) << ": "
            << answers[k].dump().substr(0, 300);
      }
    }
  }
  for (const char* method : {"mdi.execute", "program.abort"}) {
    for (std::size_t i = 0; i < params.size(); i += 3) {
      const json answer = answer_to(request(method, params[i], static_cast<int>(i)));
      ASSERT_TRUE(answer.is_object()) << method << " " << params[i].dump().substr(0, 100);
      EXPECT_EQ(answer["id"], i) << method;
      EXPECT_TRUE(answer.contains("result") != answer.contains("error")) << answer.dump();
    }
  }
  const json s = status();
  EXPECT_EQ(s["state"], "estop");
  EXPECT_EQ(s["motion"], "idle");
  EXPECT_EQ(s["position"]["commanded"], (json{{"x", 0.0}, {"y", 0.0}, {"z", 0.0}}));
}

TEST_F(MachineTest, AJointNumberPastIntIsNotJointZero) {
  const json r = call("machine.home", {{"joints", {4294967296LL}}});
  EXPECT_EQ(error_code(r), -32602) << r.dump();
}

TEST_F(MachineTest, OddIdsAndDeepNestingAreAnswered) {
  for (const json& id : {json::array({1}), json{{"a", 1}}, json(true)}) {
    const json r = json::parse(
        [&] {
          client_.send_raw(json{{"jsonrpc", "2.0"}, {"id", id}, {"method", "status.get"}}.dump() +
                           "\n");
          return client_.read_line(5000);
        }(),
        nullptr, false);
    EXPECT_EQ(r["error"]["code"], -32600) << r.dump();
  }
  // 200,000 levels of nesting inside the 1 MiB line limit, as id, as params and as a request:
  // refused before they are parsed.
  const std::string deep = std::string(200'000, '[') + std::string(200'000, ']');
  for (const std::string& line :
       {R"({"jsonrpc":"2.0","id":)" + deep + R"(,"method":"status.get"})",
        R"({"jsonrpc":"2.0","id":7,"method":"status.get","params":{"fields":)" + deep + "}}",
        deep}) {
    client_.send_raw(line + "\n");
    const json r = json::parse(client_.read_line(10000), nullptr, false);
    EXPECT_EQ(r["error"]["code"], -32600) << r.dump().substr(0, 200);
  }
  EXPECT_EQ(status()["state"], "estop");
}

}  // namespace
}  // namespace cncd::test
