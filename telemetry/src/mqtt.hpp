// MQTT through libmosquitto: cncd's state (retained), position, events and jobs under
// [TELEMETRY] TOPIC_PREFIX, with `online`/`offline` (the last will) at .../availability.
// Events and jobs are QoS 1 and kept, in order, until the broker has acknowledged them: a
// broker that is away, refuses or never answers loses none of them (up to EVENT_QUEUE; beyond,
// the oldest are dropped, counted and logged). libmosquitto's own thread talks to the broker,
// reconnecting with exponential backoff (1 s to 60 s); its callbacks are handed to the
// io_context, so everything here runs on one thread. The broker's address and credentials are
// never logged.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "mqtt_client.hpp"

struct mosquitto;

namespace cncd::telemetry {

struct MqttOptions {
  BrokerOptions broker;
  std::string prefix;  // topics are prefix + "/state" ...
  std::size_t queue = 10000;
};

class MqttPublisher {
 public:
  MqttPublisher(boost::asio::io_context& io, MqttOptions options);
  ~MqttPublisher();
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  // Starts talking to the broker; "" or what is wrong with the options (never the password).
  std::string start();
  // Retained, QoS 1; sent again at each connection.
  void state(const nlohmann::json& payload);
  // QoS 0, not retained: only while connected.
  void position(const nlohmann::json& payload);
  // QoS 1, queued until acknowledged.
  void event(const nlohmann::json& payload);
  void job(const nlohmann::json& payload);
  // Says `offline` itself (a clean end has no last will) and disconnects.
  void stop();

  bool connected() const { return connected_; }
  std::uint64_t dropped() const { return dropped_; }
  std::size_t queued() const { return queue_.size(); }

 private:
  struct Pending {
    std::string topic;
    std::string payload;
    int mid = 0;  // the message id of its last send; 0: not sent on this connection
  };
  void reliable(const std::string& suffix, const nlohmann::json& payload);
  void send_queue();
  int publish(const std::string& topic, const std::string& payload, int qos, bool retain);
  void on_connect(int rc);
  void on_disconnect(int rc);
  void on_error(const std::string& words);  // libmosquitto logged an error
  void unreachable(const std::string& why);
  void on_publish(int mid);

  boost::asio::io_context& io_;
  MqttOptions options_;
  mosquitto* mosq_ = nullptr;
  bool started_ = false;
  bool connected_ = false;
  std::string state_;  // the last state payload, sent again at each connection
  std::deque<Pending> queue_;
  std::uint64_t dropped_ = 0;
  bool unreachable_said_ = false;  // logged for this outage
  // Cleared when the publisher goes: callbacks already handed to the io_context do nothing.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace cncd::telemetry
