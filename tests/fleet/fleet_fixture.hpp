// The real cncd-fleet against a real mosquitto broker on loopback, a publisher that sends what
// a test gives it (QoS 1, waited for), and the fleet's HTTP API and WebSocket read as a browser
// would.
#pragma once

#include <mosquitto.h>
#include <sys/socket.h>

#include <atomic>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>
#include <regex>

#include "../telemetry/broker.hpp"

namespace cncd::test {

// Publishes and waits until the broker has each QoS 1 message.
class Publisher {
 public:
  explicit Publisher(int port) {
    mosquitto_lib_init();
    mosq_ = mosquitto_new(nullptr, true, this);
    mosquitto_publish_callback_set(
        mosq_, [](mosquitto*, void* self, int) { ++static_cast<Publisher*>(self)->acked_; });
    mosquitto_connect(mosq_, "127.0.0.1", port, 30);
    mosquitto_loop_start(mosq_);
  }
  ~Publisher() {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, false);
    mosquitto_destroy(mosq_);
  }
  void publish(const std::string& topic, const std::string& payload, bool retain = true,
               int qos = 1) {
    const int rc = mosquitto_publish(mosq_, nullptr, topic.c_str(),
                                     static_cast<int>(payload.size()), payload.data(), qos, retain);
    ASSERT_EQ(rc, MOSQ_ERR_SUCCESS) << topic << ": " << mosquitto_strerror(rc);
    if (qos > 0) ++sent_;
  }
  // Waits until every QoS 1 message sent so far is acknowledged.
  bool flushed() {
    for (int i = 0; i < 6000 && acked_ < sent_; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return acked_ >= sent_;
  }

 private:
  mosquitto* mosq_ = nullptr;
  std::atomic<int> acked_{0};
  int sent_ = 0;
};

class FleetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists("/usr/sbin/mosquitto"))
      GTEST_SKIP() << "mosquitto is not installed (scripts/setup.sh --with-broker)";
    ASSERT_EQ(broker_.start(), "");
  }
  void start_fleet(std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {
        CNCD_FLEET_BINARY, "--broker",    "127.0.0.1:" + std::to_string(broker_.port()),
        "--listen",        "127.0.0.1:0", "--www",
        CNCD_FLEET_WWW};
    argv.insert(argv.end(), extra.begin(), extra.end());
    fleet_ = std::make_unique<BackgroundCommand>(argv);
    const std::regex serving("serving http://127\\.0\\.0\\.1:([0-9]+)");
    for (int i = 0; i < 3000 && port_ == 0; ++i) {
      std::smatch m;
      const std::string err = fleet_->err_so_far();
      if (std::regex_search(err, m, serving) && err.find("connected to the broker") != err.npos)
        port_ = std::stoi(m[1]);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_NE(port_, 0) << fleet_->err_so_far();
  }
  HttpAnswer get(const std::string& target) {
    return http_exchange(
        port_, "GET " + target + " HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n");
  }
  nlohmann::json machines() {
    const auto answer = get("/api/machines");
    EXPECT_EQ(answer.status, 200) << fleet_->err_so_far();
    const auto parsed = nlohmann::json::parse(answer.body, nullptr, false);
    return parsed.is_object() ? parsed["machines"] : nlohmann::json::array();
  }
  // The table's row of machine `id` once `done(row)` holds (null after 30 s).
  template <typename Done>
  nlohmann::json row_when(const std::string& id, Done done) {
    for (int i = 0; i < 3000; ++i) {
      for (const auto& row : machines()) {
        if (row["id"] == id && done(row)) return row;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ADD_FAILURE() << "no row " << id << " as wanted in " << machines().dump();
    return nullptr;
  }
  bool alive() { return ::kill(fleet_->pid(), 0) == 0 && get("/api/machines").status == 200; }

  TempDir dir_;
  Broker broker_{dir_.path()};
  std::unique_ptr<BackgroundCommand> fleet_;
  int port_ = 0;
};

// A browser's WebSocket to the fleet: its frames as JSON, each read waiting at most 30 s.
class WsReader {
 public:
  explicit WsReader(int port, const std::string& origin = "") : ws_(io_) {
    namespace beast = boost::beast;
    ws_.next_layer().connect(
        {boost::asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)});
    timeval timeout{30, 0};
    ::setsockopt(ws_.next_layer().native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout,
                 sizeof timeout);
    ws_.set_option(
        beast::websocket::stream_base::decorator([origin](beast::websocket::request_type& req) {
          if (!origin.empty()) req.set(beast::http::field::origin, origin);
        }));
    ws_.handshake(response_, "127.0.0.1:" + std::to_string(port), "/ws", error_);
  }
  const boost::beast::error_code& error() const { return error_; }
  int status() const { return static_cast<int>(response_.result_int()); }
  nlohmann::json next() {
    boost::beast::flat_buffer buffer;
    boost::beast::error_code ec;
    ws_.read(buffer, ec);
    if (ec) return nullptr;
    return nlohmann::json::parse(boost::beast::buffers_to_string(buffer.data()), nullptr, false);
  }

 private:
  boost::asio::io_context io_;
  boost::beast::websocket::stream<boost::asio::ip::tcp::socket> ws_;
  boost::beast::websocket::response_type response_;
  boost::beast::error_code error_;
};

}  // namespace cncd::test
