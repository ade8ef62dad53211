#include "rpc.hpp"

#include <set>
#include <stdexcept>
#include <string_view>

#include <gtest/gtest.h>

namespace cncd::daemon {
namespace {

using nlohmann::json;

// The dispatcher's own table here: the daemon's is tested through the daemon
// (rpc_params_test.cpp).
std::vector<MethodSpec> test_table() {
  using enum ParamType;
  return {
      {"echo",
       Access::control,
       {{.name = "x", .type = integer, .min = 0, .max = 10, .note = "a digit"},
        {.name = "s", .type = string, .note = "any text"},
        {.name = "list", .type = integer_list, .min = 0, .max = 3, .note = "small numbers"}}},
      {"need", Access::control, {{.name = "n", .type = number, .required = true, .note = "any"}}},
      {"refuse", Access::control, {}},
      {"query", Access::read, {}},
      {"broken", Access::control, {{.name = "x", .type = integer, .note = "a number"}}},
  };
}

class RpcTest : public ::testing::Test {
 protected:
  RpcTest() : dispatcher_(test_table()) {}
  void SetUp() override {
    dispatcher_.add("echo", [](const json& params) { return params; });
    dispatcher_.add("need", [](const json& params) { return params; }, {{"n", 0, 5}});
    dispatcher_.add("refuse", [](const json&) -> json { throw RpcError(kWrongState, "no"); });
    dispatcher_.add("query", [](const json&) { return json(1); });
    // A handler with a fault of its own: it reads an integer as a string.
    dispatcher_.add("broken", [](const json& params) { return params["x"].get<std::string>(); });
  }
  json call(const std::string& line) {
    auto out = dispatcher_.handle_line(line, session_);
    EXPECT_TRUE(out.has_value());
    return out ? json::parse(*out) : json();
  }
  RpcDispatcher dispatcher_;
  Session session_;
};

TEST_F(RpcTest, AnswersWithResultAndSameId) {
  const json r = call(R"({"jsonrpc":"2.0","id":"a1","method":"echo","params":{"x":1}})");
  EXPECT_EQ(r["id"], "a1");
  EXPECT_EQ(r["result"]["x"], 1);
}

TEST_F(RpcTest, MalformedJsonIsParseError) {
  const json r = call("{not json");
  EXPECT_EQ(r["error"]["code"], kParseError);
  EXPECT_TRUE(r["id"].is_null());
}

TEST_F(RpcTest, UnknownMethod) {
  const json r = call(R"({"jsonrpc":"2.0","id":1,"method":"nope"})");
  EXPECT_EQ(r["error"]["code"], kMethodNotFound);
}

TEST_F(RpcTest, MissingVersionIsInvalidRequest) {
  const json r = call(R"({"id":1,"method":"echo"})");
  EXPECT_EQ(r["error"]["code"], kInvalidRequest);
}

TEST_F(RpcTest, ScalarParamsAreInvalid) {
  const json r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":3})");
  EXPECT_EQ(r["error"]["code"], kInvalidParams);
}

TEST_F(RpcTest, DeepNestingIsRefusedBeforeParsing) {
  const std::string deep = std::string(100'000, '[') + std::string(100'000, ']');
  json r = call(R"({"jsonrpc":"2.0","id":)" + deep + R"(,"method":"echo"})");
  EXPECT_EQ(r["error"]["code"], kInvalidRequest);
  EXPECT_EQ(r["error"]["message"], "request nested deeper than 64 levels");
  // Brackets inside strings do not count; 64 levels are fine.
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"s":")" + deep + R"(\""}})");
  EXPECT_TRUE(r.contains("result")) << r.dump().substr(0, 200);
  // 64 levels are parsed (and then refused as params echo does not take).
  const std::string levels_62 = std::string(62, '[') + std::string(62, ']');
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"s":)" + levels_62 + "}}");
  EXPECT_EQ(r["error"]["code"], kInvalidParams) << r.dump().substr(0, 200);
}

TEST_F(RpcTest, BatchOfMoreThan256IsRefused) {
  const auto batch = [](int n) {
    std::string out = "[";
    for (int i = 0; i < n; ++i)
      out += std::string(i > 0 ? "," : "") + R"({"jsonrpc":"2.0","id":1,"method":"echo"})";
    return out + "]";
  };
  EXPECT_EQ(call(batch(256)).size(), 256u);
  const json r = call(batch(257));
  EXPECT_EQ(r["error"]["code"], kInvalidRequest);
  EXPECT_EQ(r["error"]["message"], "a batch may hold at most 256 requests");
}

TEST_F(RpcTest, HandlerErrorKeepsItsCode) {
  const json r = call(R"({"jsonrpc":"2.0","id":7,"method":"refuse"})");
  EXPECT_EQ(r["error"]["code"], kWrongState);
  EXPECT_EQ(r["error"]["message"], "no");
  EXPECT_EQ(r["id"], 7);
}

TEST_F(RpcTest, NotificationGetsNoAnswer) {
  EXPECT_FALSE(
      dispatcher_.handle_line(R"({"jsonrpc":"2.0","method":"echo"})", session_).has_value());
}

TEST_F(RpcTest, BatchAnswersEachRequestInOrder) {
  const json r = call(R"([{"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":1}},)"
                      R"({"jsonrpc":"2.0","method":"echo"},)"
                      R"({"jsonrpc":"2.0","id":2,"method":"nope"}])");
  ASSERT_TRUE(r.is_array());
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0]["id"], 1);
  EXPECT_EQ(r[1]["error"]["code"], kMethodNotFound);
}

// The server counts a batch as the requests it holds when it shares turns between clients.
TEST_F(RpcTest, ALineTellsHowManyRequestsItHeld) {
  std::size_t requests = 0;
  dispatcher_.handle_line(R"({"jsonrpc":"2.0","id":1,"method":"query"})", session_, &requests);
  EXPECT_EQ(requests, 1u);
  dispatcher_.handle_line(R"([{"jsonrpc":"2.0","id":1,"method":"query"},)"
                          R"({"jsonrpc":"2.0","method":"query"},)"
                          R"({"jsonrpc":"2.0","id":2,"method":"nope"}])",
                          session_, &requests);
  EXPECT_EQ(requests, 3u);
  dispatcher_.handle_line("{not json", session_, &requests);
  EXPECT_EQ(requests, 1u);
}

TEST_F(RpcTest, ReaderMayQueryButNotCommand) {
  session_.access = Access::read;
  EXPECT_EQ(call(R"({"jsonrpc":"2.0","id":1,"method":"query"})")["result"], 1);
  EXPECT_EQ(call(R"({"jsonrpc":"2.0","id":2,"method":"echo"})")["error"]["code"],
            kPermissionDenied);
}

// The error object of an answer (empty, with a failure, for a result).
json error_of(const json& r) {
  EXPECT_TRUE(r.contains("error")) << r.dump();
  return r.value("error", json::object());
}

// The message of a -32602 answer.
std::string invalid_params(const json& r) {
  EXPECT_EQ(error_of(r)["code"], kInvalidParams) << r.dump();
  return error_of(r).value("message", "");
}

TEST_F(RpcTest, UnknownParameterIsRefusedNamingIt) {
  json r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":1,"lst":[1]}})");
  EXPECT_EQ(invalid_params(r), "unknown parameter \"lst\" (echo takes: x, s, list)");
  r = call(R"({"jsonrpc":"2.0","id":2,"method":"refuse","params":{"x":1}})");
  EXPECT_EQ(invalid_params(r), "unknown parameter \"x\" (refuse takes no parameters)");
  // A misspelling is named before a required parameter is found missing.
  r = call(R"({"jsonrpc":"2.0","id":3,"method":"need","params":{"N":1}})");
  EXPECT_EQ(invalid_params(r), "unknown parameter \"N\" (need takes: n)");
}

TEST_F(RpcTest, WrongTypesAreRefusedNamingParameterAndType) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"x":"1"})", R"(parameter "x" must be an integer from 0 to 10 (a digit), not "1")"},
      {R"({"x":true})", R"(parameter "x" must be an integer from 0 to 10 (a digit), not true)"},
      {R"({"x":[1]})", R"(parameter "x" must be an integer from 0 to 10 (a digit), not [1])"},
      {R"({"s":1})", R"(parameter "s" must be a string (any text), not 1)"},
      {R"({"list":3})", "parameter \"list\" must be an array of integers from 0 to 3"},
      {R"({"list":[1,"2"]})", R"(from 0 to 3 (small numbers), not [1,"2"])"},
      {R"({"list":[1,7]})", R"(from 0 to 3 (small numbers), not [1,7])"},
      // A long list is shown cut short, followed by the item at fault.
      {R"({"list":[0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,"x"]})",
       R"(not [0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0... (it holds "x"))"},
  };
  for (const auto& [params, message] : cases) {
    const json r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":)" + params + "}");
    EXPECT_NE(invalid_params(r).find(message), std::string::npos) << params << ": " << r.dump();
  }
  const json r = call(R"({"jsonrpc":"2.0","id":1,"method":"need","params":{"n":"5"}})");
  EXPECT_EQ(invalid_params(r), R"(parameter "n" must be a number from 0 to 5 (any), not "5")");
}

TEST_F(RpcTest, FractionsAreNotIntegers) {
  json r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":1.5}})");
  EXPECT_EQ(invalid_params(r),
            R"(parameter "x" must be an integer from 0 to 10 (a digit), not 1.5)");
  for (const char* whole : {"2.0", "2e0"}) {
    r = call(std::string(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":)") + whole +
             "}}");
    EXPECT_NE(invalid_params(r).find("(an integer is written without a fraction or exponent)"),
              std::string::npos)
        << r.dump();
  }
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"list":[0,2.5]}})");
  EXPECT_NE(invalid_params(r).find("not [0,2.5]"), std::string::npos) << r.dump();
  EXPECT_EQ(call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":2}})")["result"],
            (json{{"x", 2}}));
}

TEST_F(RpcTest, RangesAreChecked) {
  json r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":11}})");
  EXPECT_EQ(invalid_params(r),
            R"(parameter "x" must be an integer from 0 to 10 (a digit), not 11)");
  // The range given when the handler was added.
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"need","params":{"n":5.5}})");
  EXPECT_EQ(invalid_params(r), R"(parameter "n" must be a number from 0 to 5 (any), not 5.5)");
  EXPECT_EQ(call(R"({"jsonrpc":"2.0","id":1,"method":"need","params":{"n":5}})")["result"]["n"], 5);
}

TEST_F(RpcTest, MissingAndNullParameters) {
  json r = call(R"({"jsonrpc":"2.0","id":1,"method":"need","params":{}})");
  EXPECT_EQ(invalid_params(r),
            R"(parameter "n" is missing; it must be a number from 0 to 5 (any))");
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"need","params":{"n":null}})");
  EXPECT_EQ(invalid_params(r), R"(parameter "n" must be a number from 0 to 5 (any), not null)");
  // An optional parameter given as null is left out.
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":null,"s":"a"}})");
  EXPECT_EQ(r["result"], (json{{"s", "a"}})) << r.dump();
}

TEST_F(RpcTest, ParamsMustBeNamed) {
  for (const char* params : {"[1]", "\"x\"", "3", "true"}) {
    const json r =
        call(std::string(R"({"jsonrpc":"2.0","id":1,"method":"need","params":)") + params + "}");
    EXPECT_NE(invalid_params(r).find("params must be an object of named parameters, not "),
              std::string::npos);
    EXPECT_NE(error_of(r)
                  .value("message", "")
                  .find(R"(need takes: "n", a number from 0 to 5 (any), required)"),
              std::string::npos)
        << r.dump();
  }
  // Left out, null, {} and [] all say nothing.
  for (const char* params : {"", R"(,"params":null)", R"(,"params":{})", R"(,"params":[])"}) {
    const json r = call(std::string(R"({"jsonrpc":"2.0","id":1,"method":"echo")") + params + "}");
    EXPECT_EQ(r.value("result", json()), json::object()) << params << ": " << r.dump();
  }
}

TEST_F(RpcTest, LibraryErrorsAreNotShownToTheClient) {
  const json r = call(R"({"jsonrpc":"2.0","id":1,"method":"broken","params":{"x":1}})");
  EXPECT_EQ(error_of(r)["code"], kInternalError) << r.dump();
  EXPECT_EQ(error_of(r).value("message", "").find("json"), std::string::npos) << r.dump();
}

TEST_F(RpcTest, DuplicateKeysAreInvalidRequests) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {R"({"jsonrpc":"2.0","id":1,"method":"echo","method":"refuse"})", "method"},
      {R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":1,"x":2}})", "x"},
      {R"({"jsonrpc":"2.0","jsonrpc":"2.0","id":1,"method":"echo"})", "jsonrpc"},
      {R"({"jsonrpc":"2.0","id":1,"method":"echo","params":{"s":"a"},"params":{}})", "params"},
  };
  for (const auto& [line, key] : cases) {
    const json r = call(line);
    EXPECT_EQ(error_of(r)["code"], kInvalidRequest) << line;
    EXPECT_EQ(error_of(r)["message"],
              "duplicate key \"" + key + "\": a request names each key of an object once");
    EXPECT_EQ(r["id"], 1) << line;
  }
  // Repeated ids: which one is meant is unknown, so the answer has none.
  json r = call(R"({"jsonrpc":"2.0","id":1,"id":2,"method":"echo"})");
  EXPECT_EQ(error_of(r)["code"], kInvalidRequest);
  EXPECT_TRUE(r["id"].is_null()) << r.dump();
  // An "id" repeated inside params is not the request's id.
  r = call(R"({"jsonrpc":"2.0","id":3,"method":"echo","params":{"id":1,"id":2}})");
  EXPECT_EQ(error_of(r)["code"], kInvalidRequest);
  EXPECT_EQ(r["id"], 3);
  // A notification with a repeated key is not carried out and not answered.
  EXPECT_FALSE(
      dispatcher_
          .handle_line(R"({"jsonrpc":"2.0","method":"need","params":{"n":1,"n":2}})", session_)
          .has_value());
}

TEST_F(RpcTest, ADuplicateKeyRefusesOnlyItsRequestInABatch) {
  const json r = call(R"([{"jsonrpc":"2.0","id":1,"method":"echo","params":{"x":1}},)"
                      R"(7,)"
                      R"({"jsonrpc":"2.0","id":2,"method":"echo","params":{"s":"a","s":"b"}},)"
                      R"([1,{"a":1}],)"
                      R"({"jsonrpc":"2.0","id":3,"method":"echo","params":{"s":"c"}}])");
  ASSERT_TRUE(r.is_array()) << r.dump();
  ASSERT_EQ(r.size(), 5u) << r.dump();
  EXPECT_EQ(r[0].value("result", json()), (json{{"x", 1}}));
  EXPECT_EQ(error_of(r[1])["code"], kInvalidRequest);
  EXPECT_EQ(r[2]["id"], 2);
  EXPECT_EQ(error_of(r[2])["message"],
            "duplicate key \"s\": a request names each key of an object once");
  EXPECT_EQ(error_of(r[3])["code"], kInvalidRequest);
  EXPECT_EQ(r[4].value("result", json()), (json{{"s", "c"}}));
}

TEST(RpcTableTest, OnlyDeclaredMethodsCanBeAdded) {
  RpcDispatcher dispatcher(test_table());
  const auto nothing = [](const json&) { return json(); };
  EXPECT_THROW(dispatcher.add("undeclared", nothing), std::logic_error);
  dispatcher.add("echo", nothing);
  EXPECT_THROW(dispatcher.add("echo", nothing), std::logic_error);
  EXPECT_THROW(dispatcher.add("need", nothing, {{"m", 0, 1}}), std::logic_error);
  try {
    dispatcher.require_all_added();
    ADD_FAILURE() << "methods without handlers were not found";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "methods without a handler: broken, need, query, refuse");
  }
  // Nor is a string parameter given a range.
  EXPECT_THROW(dispatcher.add("echo", nothing, {{"s", 0, 1}}), std::logic_error);
}

TEST(RpcTableTest, TheDaemonTableDeclaresEachMethodAndParameterOnce) {
  std::set<std::string_view> methods;
  for (const auto& method : method_table()) {
    EXPECT_TRUE(methods.insert(method.name).second) << method.name;
    std::set<std::string_view> params;
    for (const auto& param : method.params)
      EXPECT_TRUE(params.insert(param.name).second) << method.name << " " << param.name;
  }
  EXPECT_NO_THROW(RpcDispatcher());
}

TEST_F(RpcTest, EmptyBatchIsInvalid) {
  EXPECT_EQ(call("[]")["error"]["code"], kInvalidRequest);
}

}  // namespace
}  // namespace cncd::daemon
