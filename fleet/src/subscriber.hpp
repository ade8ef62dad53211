// The fleet page's one MQTT client (libmosquitto): subscribes to the pattern's state,
// availability and events topics, at QoS 0 (the page shows the latest state, retained and
// sent again at each connection; a state superseded meanwhile is not worth an acknowledgement
// each: at 5000 messages a second QoS 1 held the page seconds behind), and hands every message
// to the io_context's thread. Its own
// thread reconnects with exponential backoff (1 s to 60 s) and subscribes again, so the
// broker's retained states fill the table anew. A payload over the limit is dropped on that
// thread unread, and so is anything beyond `max_pending` messages not yet taken by the
// io_context (a stalled page cannot make it buffer without bound). The broker's address and
// credentials are never logged.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "mqtt_client.hpp"

struct mosquitto;

namespace cncd::fleet {

using telemetry::BrokerOptions;

struct SubscriberHandlers {
  std::function<void(std::string topic, std::string payload)> message;
  std::function<void(std::string topic, std::size_t bytes)> too_large;
  std::function<void(bool connected)> connection;
};

class Subscriber {
 public:
  Subscriber(boost::asio::io_context& io, BrokerOptions options, std::vector<std::string> filters,
             std::size_t max_payload, SubscriberHandlers handlers);
  ~Subscriber();
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  // "" or what is wrong with the options (never the password).
  std::string start();
  void stop();
  std::uint64_t dropped() const { return dropped_; }

  static constexpr std::size_t max_pending = 100000;

 private:
  void deliver(std::string topic, std::string payload);

  boost::asio::io_context& io_;
  BrokerOptions options_;
  std::vector<std::string> filters_;
  std::size_t max_payload_;
  SubscriberHandlers handlers_;
  mosquitto* mosq_ = nullptr;
  bool started_ = false;
  std::atomic<std::size_t> pending_{0};
  std::atomic<std::uint64_t> dropped_{0};
  // Cleared when the subscriber goes: callbacks already posted do nothing.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace cncd::fleet
