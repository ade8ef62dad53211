// Requests mean exactly what they say: every method the daemon serves refuses a parameter it
// does not take, one of the wrong type and a request with a repeated key, over the real socket;
// the parameters it does take are accepted; docs/protocol.md lists the same parameters.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "machine_fixture.hpp"
#include "rpc_params.hpp"

namespace cncd::test {
namespace {

using daemon::MethodSpec;
using daemon::ParamSpec;
using daemon::ParamType;
using nlohmann::json;

const MethodSpec* find_method(const std::string& name) {
  for (const auto& method : daemon::method_table()) {
    if (method.name == name) return &method;
  }
  return nullptr;
}

// Misspellings a client might make of `name`: fromline, joint, Axis ...
std::vector<std::string> misspellings(std::string_view name) {
  const std::string n(name);
  std::vector<std::string> out;
  if (const auto u = n.find('_'); u != std::string::npos)
    out.push_back(n.substr(0, u) + n.substr(u + 1));
  out.push_back(n.back() == 's' ? n.substr(0, n.size() - 1) : n + "s");
  std::string capital = n;
  capital[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(capital[0])));
  out.push_back(capital);
  return out;
}

// Values of every type but `type`, including fractions and 2.0 where an integer is meant.
std::vector<json> wrong_values(ParamType type) {
  switch (type) {
    case ParamType::integer:
      return {"1", 1.5, 2.0, true, json::array({1}), json::object()};
    case ParamType::number:
      return {"1", true, json::array({1}), json{{"a", 1}}};
    case ParamType::string:
      return {1, true, json::array({"X"}), json::object()};
    case ParamType::string_list:
      return {"state", json::array({1}), json::object()};
    case ParamType::integer_list:
      return {0, json::array({0.5}), json::array({"0"}), json::array({1.0})};
    case ParamType::axis_values:
      return {1, "x", json::array({1})};
    case ParamType::coord_system:
      return {1.5, 2.0, true, json::array({1}), json::object()};
  }
  return {};
}

std::string type_phrase(ParamType type) {
  static const std::map<ParamType, std::string> kPhrases = {
      {ParamType::integer, "an integer"},
      {ParamType::number, "a number"},
      {ParamType::string, "a string"},
      {ParamType::string_list, "an array of strings"},
      {ParamType::integer_list, "an array of integers"},
      {ParamType::axis_values, "an object of axis values"},
      {ParamType::coord_system, "a coordinate system"},
  };
  const auto it = kPhrases.find(type);
  return it != kPhrases.end() ? it->second : "?";
}

class RpcParamsTest : public MachineTest {
 protected:
  // The parameters that stand instead of another one (a jog's "joint" for its "axis"), each
  // in a request the daemon accepts.
  static json alternative_params() {
    return {
        {"jog.start", {{"joint", 0}, {"velocity", 1}}},
        {"jog.stop", {{"joint", 0}}},
        {"jog.heartbeat", {{"joint", 0}}},
        {"jog.increment", {{"joint", 0}, {"distance", 1}}},
    };
  }

  // Every parameter of every method, spelt right, with a value the daemon accepts.
  json valid_params() {
    const auto program = dir_.write("ok.ngc", "G21 G90\nG0 X1\nM2\n");
    return {
        {"status.get", {{"fields", {"state"}}}},
        {"status.subscribe", {{"interval_ms", 1000}, {"fields", {"state"}}}},
        {"errors.list", {{"since", 0}}},
        {"jobs.history", {{"since", 0}, {"limit", 10}}},
        {"jobs.stats", {{"since", 1.5}}},
        {"machine.home", {{"joints", {0}}}},
        {"jog.start", {{"axis", "X"}, {"velocity", 1}, {"heartbeat_s", 0.5}}},
        {"jog.stop", {{"axis", "X"}}},
        {"jog.heartbeat", {{"axis", "X"}}},
        {"jog.increment", {{"axis", "x"}, {"distance", 1}, {"velocity", 1.5}}},
        {"program.open", {{"path", program.string()}}},
        {"program.preview", {{"tolerance", 0.05}}},
        {"program.run", {{"from_line", 1}}},
        {"mdi.execute", {{"line", "G0 X0"}}},
        {"override.feed", {{"value", 1.0}}},
        {"override.rapid", {{"value", 1}}},
        {"override.spindle", {{"value", 1}}},
        {"tool.set",
         {{"number", 1},
          {"pocket", 1},
          {"offset", {{"z", 0}}},
          {"diameter", 6},
          {"front_angle", 0},
          {"back_angle", 0},
          {"orientation", 0},
          {"comment", "6 mm end mill"}}},
        {"tool.change_done", {{"tool", 3}}},
        {"wait.done", {{"kind", "input"}}},
        // sim_mm.ini: DIGITAL_INPUT_0 = sim:door_closed.
        {"sim.set", {{"signal", "door_closed"}, {"value", 1}}},
        {"offsets.set", {{"system", "G54"}, {"origin", {{"x", 0}}}, {"rotation", 0}}},
    };
  }

  // Sends one line as it is; the answer to it (past notifications).
  json send_line(const std::string& line) {
    client_.send_raw(line + "\n");
    json answer;
    do {
      answer = json::parse(client_.read_line(10000), nullptr, false);
    } while (answer.is_object() && answer.contains("method"));
    return answer;
  }
};

int code_of(const json& r) {
  return r.value("error", json::object()).value("code", 0);
}

std::string message_of(const json& r) {
  return r.value("error", json::object()).value("message", "");
}

TEST_F(RpcParamsTest, TableListsEveryServedMethod) {
  std::set<std::string> table;
  for (const auto& method : daemon::method_table())
    table.emplace(method.name);
  EXPECT_EQ(table, std::set<std::string>(served_methods().begin(), served_methods().end()));
  // And the daemon serves each of them.
  for (const auto& method : served_methods())
    EXPECT_NE(code_of(call(method, {{"bogus", 1}})), -32601) << method;
  EXPECT_EQ(code_of(call("machine.bogus")), -32601);
}

TEST_F(RpcParamsTest, EveryMethodRefusesAMisspeltParameterNamingIt) {
  const json valid = valid_params();
  for (const auto& name : served_methods()) {
    const MethodSpec* method = find_method(name);
    ASSERT_NE(method, nullptr) << name << " has no entry in the method table";
    std::vector<std::string> wrong = {"bogus"};
    for (const auto& param : method->params) {
      for (auto& m : misspellings(param.name))
        wrong.push_back(std::move(m));
    }
    for (const auto& misspelt : wrong) {
      // Alone, and beside every parameter spelt right.
      json alone = {{misspelt, 1}};
      json beside = valid.value(name, json::object());
      beside[misspelt] = 1;
      for (const json& params : {alone, beside}) {
        const json r = call(name, params);
        EXPECT_EQ(code_of(r), -32602) << name << " " << params.dump() << ": " << r.dump();
        EXPECT_NE(message_of(r).find("unknown parameter \"" + misspelt + "\" (" + name + " takes"),
                  std::string::npos)
            << r.dump();
      }
    }
  }
  // Nothing happened: the machine is still in estop, unhomed, with no program.
  const json s = status();
  EXPECT_EQ(s["state"], "estop");
  EXPECT_EQ(s["homed"], json::array({false, false, false}));
  EXPECT_EQ(s["program"]["path"], "");
}

TEST_F(RpcParamsTest, MisspeltParametersAreNotIgnored) {
  ready_machine();
  const auto program = dir_.write("lines.ngc", "G21 G90\nG0 X1\nG0 X2\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  json r = call("program.run", {{"fromline", 3}});
  EXPECT_EQ(code_of(r), -32602);
  EXPECT_EQ(message_of(r), "unknown parameter \"fromline\" (program.run takes: from_line)");
  EXPECT_EQ(status()["exec"], "idle");
  r = call("machine.home", {{"joint", {0}}});
  EXPECT_EQ(message_of(r), "unknown parameter \"joint\" (machine.home takes: joints)");
  EXPECT_EQ(status()["motion"], "idle");
}

TEST_F(RpcParamsTest, WrongTypesAreRefusedNamingParameterAndType) {
  for (const auto& method : daemon::method_table()) {
    for (const ParamSpec& param : method.params) {
      std::vector<json> values = wrong_values(param.type);
      if (param.required) values.emplace_back(nullptr);
      for (const auto& value : values) {
        const std::string name(method.name);
        const json r = call(name, {{std::string(param.name), value}});
        const std::string message = message_of(r);
        EXPECT_EQ(code_of(r), -32602) << name << " " << value.dump() << ": " << r.dump();
        EXPECT_EQ(message.rfind("parameter \"" + std::string(param.name) + "\" must be ", 0), 0u)
            << name << ": " << message;
        EXPECT_NE(message.find(" must be " + type_phrase(param.type)), std::string::npos)
            << message;
        EXPECT_EQ(message.find("json"), std::string::npos) << message;
      }
    }
  }
  EXPECT_EQ(status()["state"], "estop");
}

TEST_F(RpcParamsTest, FractionsAreRefusedWhereAnIntegerIsMeant) {
  const std::vector<std::tuple<std::string, json, std::string>> cases = {
      {"machine.home", {{"joints", {1.5}}}, "\"joints\" must be an array of integers from 0 to 2"},
      {"program.run", {{"from_line", 2.5}}, "\"from_line\" must be an integer from 1"},
      {"status.subscribe", {{"interval_ms", 100.5}}, "\"interval_ms\" must be an integer"},
      {"errors.list", {{"since", 0.5}}, "\"since\" must be an integer"},
      {"tool.set", {{"number", 1.5}}, "\"number\" must be an integer from 1 to 99999"},
      {"tool.set", {{"number", 2.0}}, "not 2.0 (an integer is written without a fraction"},
      {"offsets.set", {{"system", 2.0}}, "\"system\" must be a coordinate system"},
  };
  for (const auto& [method, params, message] : cases) {
    const json r = call(method, params);
    EXPECT_EQ(code_of(r), -32602) << method << " " << params.dump();
    EXPECT_NE(message_of(r).find(message), std::string::npos) << r.dump();
  }
}

TEST_F(RpcParamsTest, ParamsMustBeAnObject) {
  for (const auto& name : served_methods()) {
    for (const json& params : {json::array({"X"}), json("X"), json(1)}) {
      const json r = call(name, params);
      EXPECT_EQ(code_of(r), -32602) << name << " " << params.dump();
      EXPECT_EQ(message_of(r).rfind("params must be an object of named parameters, not ", 0), 0u)
          << r.dump();
    }
  }
}

TEST_F(RpcParamsTest, RepeatedKeysAreRefused) {
  json r =
      send_line(R"({"jsonrpc":"2.0","id":1,"method":"jog.stop","params":{"axis":"X","axis":"Y"}})");
  EXPECT_EQ(code_of(r), -32600) << r.dump();
  EXPECT_EQ(r["id"], 1);
  EXPECT_EQ(message_of(r), "duplicate key \"axis\": a request names each key of an object once");
  r = send_line(R"({"jsonrpc":"2.0","id":2,"method":"status.get","method":"machine.reset"})");
  EXPECT_EQ(code_of(r), -32600) << r.dump();
  // Deeper inside params too: nothing is set.
  r = send_line(R"({"jsonrpc":"2.0","id":3,"method":"offsets.set",)"
                R"("params":{"system":"G54","origin":{"x":5,"x":7}}})");
  EXPECT_EQ(code_of(r), -32600) << r.dump();
  EXPECT_EQ(message_of(r), "duplicate key \"x\": a request names each key of an object once");
  EXPECT_EQ(result_of(call("offsets.get"))["systems"][0]["origin"]["x"], 0.0);
  // In a batch, only the request with the repeated key is refused.
  r = send_line(
      R"([{"jsonrpc":"2.0","id":4,"method":"override.rapid","params":{"value":0.5}},)"
      R"({"jsonrpc":"2.0","id":5,"method":"override.feed","params":{"value":0.5,"value":1}}])");
  ASSERT_TRUE(r.is_array()) << r.dump();
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].value("result", json()), (json{{"value", 0.5}}));
  EXPECT_EQ(code_of(r[1]), -32600);
  EXPECT_EQ(r[1]["id"], 5);
  EXPECT_EQ(status()["overrides"], (json{{"feed", 1.0}, {"rapid", 0.5}, {"spindle", 1.0}}));
  EXPECT_EQ(status()["state"], "estop");
}

TEST_F(RpcParamsTest, EveryParameterSpeltRightIsAccepted) {
  const json valid = valid_params();
  const json alternatives = alternative_params();
  // Each parameter in the table is given here once, or instead of another.
  for (const auto& method : daemon::method_table()) {
    const std::string name(method.name);
    for (const auto& param : method.params) {
      EXPECT_TRUE(valid.value(name, json::object()).contains(param.name) ||
                  alternatives.value(name, json::object()).contains(param.name))
          << method.name << " " << param.name;
    }
  }
  for (const auto& [name, params] : alternatives.items()) {
    const json r = call(name, params);
    const int code = code_of(r);
    EXPECT_TRUE(r.contains("result") || (code != -32600 && code != -32601 && code != -32602))
        << name << ": " << r.dump();
  }
  // In table order: the machine goes from estop to off, on and off again; what a state does
  // not allow is refused for that reason, never for its parameters.
  for (const auto& method : daemon::method_table()) {
    const std::string name(method.name);
    const json r = call(name, valid.value(name, json()));
    const int code = code_of(r);
    EXPECT_TRUE(r.contains("result") || (code != -32600 && code != -32601 && code != -32602))
        << name << ": " << r.dump();
  }
  // The absent, null and empty forms of optional parameters are accepted too.
  result_of(call("status.get", json::object()));
  result_of(call("status.get", json::array()));
  result_of(call("status.get", {{"fields", nullptr}}));
  result_of(call("errors.list", {{"since", nullptr}}));
}

// docs/protocol.md's parameter table: | `method` | `param` | type | required | values |, and
// | `method` | — | | | | for a method without parameters.
TEST(ProtocolDocsTest, ParameterTableMatchesTheMethodTable) {
  std::ifstream in(std::string(CNCD_SOURCE_DIR) + "/docs/protocol.md");
  ASSERT_TRUE(in) << "docs/protocol.md not found";
  using Row = std::tuple<std::string, std::string, std::string, std::string>;
  std::set<Row> documented;
  std::string line;
  bool in_section = false;
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## Parameters";
    if (!in_section || line.rfind("| `", 0) != 0) continue;
    std::vector<std::string> cells;
    std::stringstream row(line.substr(1));
    for (std::string cell; std::getline(row, cell, '|');) {
      cell.erase(0, cell.find_first_not_of(' '));
      cell.erase(cell.find_last_not_of(' ') + 1);
      cells.push_back(cell);
    }
    ASSERT_GE(cells.size(), 4u) << line;
    const auto unquote = [](const std::string& cell) {
      return cell.size() >= 2 && cell.front() == '`' ? cell.substr(1, cell.size() - 2) : cell;
    };
    EXPECT_TRUE(documented.emplace(unquote(cells[0]), unquote(cells[1]), cells[2], cells[3]).second)
        << "listed twice: " << line;
  }
  const auto text = [](const Row& row) {
    const auto& [method, param, type, required] = row;
    if (param == "—") return method + " (no parameters)";
    return method + " " + param + " (" + type + ", required: " + required + ")";
  };
  std::set<Row> declared;
  for (const auto& method : daemon::method_table()) {
    if (method.params.empty()) declared.emplace(std::string(method.name), "—", "", "");
    for (const auto& param : method.params) {
      declared.emplace(std::string(method.name), std::string(param.name),
                       std::string(daemon::type_name(param.type)), param.required ? "yes" : "no");
    }
  }
  for (const auto& row : declared)
    EXPECT_TRUE(documented.contains(row)) << "docs/protocol.md does not list " << text(row);
  for (const auto& row : documented) {
    EXPECT_TRUE(declared.contains(row))
        << "docs/protocol.md lists " << text(row) << ", which the method table does not";
  }
}

}  // namespace
}  // namespace cncd::test
