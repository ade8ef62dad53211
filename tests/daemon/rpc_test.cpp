#include "rpc.hpp"

#include <gtest/gtest.h>

namespace cncd::daemon {
namespace {

using nlohmann::json;

class RpcTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dispatcher_.add("echo", [](const json& params) { return params; });
    dispatcher_.add("refuse", [](const json&) -> json { throw RpcError(kWrongState, "no"); });
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
  const std::string levels_64 = std::string(63, '[') + std::string(63, ']');
  r = call(R"({"jsonrpc":"2.0","id":1,"method":"echo","params":)" + levels_64 + "}");
  EXPECT_TRUE(r.contains("result")) << r.dump().substr(0, 200);
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
  const json r = call(R"([{"jsonrpc":"2.0","id":1,"method":"echo","params":[1]},)"
                      R"({"jsonrpc":"2.0","method":"echo"},)"
                      R"({"jsonrpc":"2.0","id":2,"method":"nope"}])");
  ASSERT_TRUE(r.is_array());
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0]["id"], 1);
  EXPECT_EQ(r[1]["error"]["code"], kMethodNotFound);
}

TEST_F(RpcTest, ReaderMayQueryButNotCommand) {
  dispatcher_.add(
      "query", [](const json&) { return json(1); }, Access::read);
  session_.access = Access::read;
  EXPECT_EQ(call(R"({"jsonrpc":"2.0","id":1,"method":"query"})")["result"], 1);
  EXPECT_EQ(call(R"({"jsonrpc":"2.0","id":2,"method":"echo"})")["error"]["code"],
            kPermissionDenied);
}

TEST_F(RpcTest, EmptyBatchIsInvalid) {
  EXPECT_EQ(call("[]")["error"]["code"], kInvalidRequest);
}

}  // namespace
}  // namespace cncd::daemon
