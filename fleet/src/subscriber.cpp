#include "subscriber.hpp"

#include <mosquitto.h>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

namespace cncd::fleet {

Subscriber::Subscriber(boost::asio::io_context& io, BrokerOptions options,
                       std::vector<std::string> filters, std::size_t max_payload,
                       SubscriberHandlers handlers)
    : io_(io),
      options_(std::move(options)),
      filters_(std::move(filters)),
      max_payload_(max_payload),
      handlers_(std::move(handlers)) {}

Subscriber::~Subscriber() {
  *alive_ = false;
  stop();
  if (mosq_ != nullptr) mosquitto_destroy(mosq_);
}

std::string Subscriber::start() {
  std::string error;
  mosq_ = telemetry::new_client(options_, this, error);
  if (mosq_ == nullptr) return error;
  // These run on libmosquitto's thread.
  mosquitto_connect_callback_set(mosq_, [](mosquitto* m, void* self, int rc) {
    auto* me = static_cast<Subscriber*>(self);
    if (rc == 0) {
      for (const auto& filter : me->filters_)
        mosquitto_subscribe(m, nullptr, filter.c_str(), 0);
    }
    boost::asio::post(me->io_, [me, alive = me->alive_, rc] {
      if (!*alive) return;
      if (rc != 0) {
        spdlog::warn("MQTT: the broker refused the connection: {}", mosquitto_connack_string(rc));
        return;
      }
      spdlog::info("MQTT: connected to the broker");
      if (me->handlers_.connection) me->handlers_.connection(true);
    });
  });
  mosquitto_disconnect_callback_set(mosq_, [](mosquitto*, void* self, int) {
    auto* me = static_cast<Subscriber*>(self);
    boost::asio::post(me->io_, [me, alive = me->alive_] {
      if (!*alive) return;
      spdlog::warn("MQTT: the broker's connection is lost; trying again");
      if (me->handlers_.connection) me->handlers_.connection(false);
    });
  });
  mosquitto_message_callback_set(mosq_, [](mosquitto*, void* self, const mosquitto_message* m) {
    auto* me = static_cast<Subscriber*>(self);
    const auto bytes = static_cast<std::size_t>(m->payloadlen);
    if (bytes > me->max_payload_) {
      boost::asio::post(me->io_, [me, alive = me->alive_, topic = std::string(m->topic), bytes] {
        if (*alive && me->handlers_.too_large) me->handlers_.too_large(topic, bytes);
      });
      return;
    }
    me->deliver(m->topic, std::string(static_cast<const char*>(m->payload), bytes));
  });
  std::string first_failure;
  if (auto problem = telemetry::connect_in_background(mosq_, options_, first_failure);
      !problem.empty())
    return problem;
  started_ = true;
  if (!first_failure.empty())
    spdlog::warn("MQTT: cannot reach the broker: {}; trying again", first_failure);
  return "";
}

void Subscriber::deliver(std::string topic, std::string payload) {
  if (pending_.load() >= max_pending) {
    const auto n = ++dropped_;
    if ((n & (n - 1)) == 0)
      boost::asio::post(io_, [n] {
        spdlog::warn("MQTT: {} messages dropped, more than {} waiting", n, max_pending);
      });
    return;
  }
  ++pending_;
  boost::asio::post(io_, [this, alive = alive_, topic = std::move(topic),
                          payload = std::move(payload)]() mutable {
    if (!*alive) return;
    --pending_;
    handlers_.message(std::move(topic), std::move(payload));
  });
}

void Subscriber::stop() {
  if (!started_) return;
  started_ = false;
  mosquitto_disconnect(mosq_);
  mosquitto_loop_stop(mosq_, false);
}

}  // namespace cncd::fleet
