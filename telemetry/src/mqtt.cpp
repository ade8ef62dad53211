#include "mqtt.hpp"

#include <mosquitto.h>

#include <cstring>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

namespace cncd::telemetry {

using nlohmann::json;

namespace {

std::string dump(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace

MqttPublisher::MqttPublisher(boost::asio::io_context& io, MqttOptions options)
    : io_(io), options_(std::move(options)) {}

MqttPublisher::~MqttPublisher() {
  *alive_ = false;
  if (mosq_ != nullptr) {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, true);
    mosquitto_destroy(mosq_);
  }
}

std::string MqttPublisher::start() {
  std::string error;
  mosq_ = new_client(options_.broker, this, error);
  if (mosq_ == nullptr) return error;
  const std::string will = "offline";
  const std::string availability = options_.prefix + "/availability";
  mosquitto_will_set(mosq_, availability.c_str(), static_cast<int>(will.size()), will.data(), 1,
                     true);
  // libmosquitto's thread calls these; the work is done on the io_context's.
  mosquitto_connect_callback_set(mosq_, [](mosquitto*, void* self, int rc) {
    auto* me = static_cast<MqttPublisher*>(self);
    boost::asio::post(me->io_, [me, alive = me->alive_, rc] {
      if (*alive) me->on_connect(rc);
    });
  });
  mosquitto_disconnect_callback_set(mosq_, [](mosquitto*, void* self, int rc) {
    auto* me = static_cast<MqttPublisher*>(self);
    boost::asio::post(me->io_, [me, alive = me->alive_, rc] {
      if (*alive) me->on_disconnect(rc);
    });
  });
  // libmosquitto's own words on a failure (a TLS certificate it does not trust: no
  // disconnect is reported for a handshake that failed); they name neither the broker nor the
  // credentials.
  mosquitto_log_callback_set(mosq_, [](mosquitto*, void* self, int level, const char* text) {
    if ((level & MOSQ_LOG_ERR) == 0 || text == nullptr) return;
    auto* me = static_cast<MqttPublisher*>(self);
    boost::asio::post(me->io_,
                      [me, alive = me->alive_, words = std::string(text, strnlen(text, 300))] {
                        if (*alive) me->on_error(words);
                      });
  });
  mosquitto_publish_callback_set(mosq_, [](mosquitto*, void* self, int mid) {
    auto* me = static_cast<MqttPublisher*>(self);
    boost::asio::post(me->io_, [me, alive = me->alive_, mid] {
      if (*alive) me->on_publish(mid);
    });
  });
  std::string first_failure;
  if (auto problem = connect_in_background(mosq_, options_.broker, first_failure); !problem.empty())
    return problem;
  started_ = true;
  if (!first_failure.empty()) unreachable(first_failure);
  return "";
}

int MqttPublisher::publish(const std::string& topic, const std::string& payload, int qos,
                           bool retain) {
  int mid = 0;
  const int rc = mosquitto_publish(mosq_, &mid, topic.c_str(), static_cast<int>(payload.size()),
                                   payload.data(), qos, retain);
  return rc == MOSQ_ERR_SUCCESS ? mid : 0;
}

void MqttPublisher::state(const json& payload) {
  state_ = dump(payload);
  if (connected_) publish(options_.prefix + "/state", state_, 1, true);
}

void MqttPublisher::position(const json& payload) {
  if (connected_) publish(options_.prefix + "/position", dump(payload), 0, false);
}

void MqttPublisher::event(const json& payload) {
  reliable("/events", payload);
}

void MqttPublisher::job(const json& payload) {
  reliable("/job", payload);
}

void MqttPublisher::reliable(const std::string& suffix, const json& payload) {
  if (!started_) return;
  if (queue_.size() >= options_.queue) {
    queue_.pop_front();
    // Logged at each power of two, not at every message of a long outage.
    ++dropped_;
    if ((dropped_ & (dropped_ - 1)) == 0)
      spdlog::warn("MQTT: {} messages dropped unsent, the queue holding {}", dropped_,
                   options_.queue);
  }
  queue_.push_back({options_.prefix + suffix, dump(payload), 0});
  if (connected_) send_queue();
}

// Sends, in order, what has not been sent on this connection.
void MqttPublisher::send_queue() {
  for (auto& pending : queue_) {
    if (pending.mid != 0) continue;
    pending.mid = publish(pending.topic, pending.payload, 1, false);
    if (pending.mid == 0) return;  // the connection went: all again at the next
  }
}

void MqttPublisher::on_connect(int rc) {
  if (rc != 0) {
    spdlog::warn("MQTT: the broker refused the connection: {}", mosquitto_connack_string(rc));
    return;
  }
  spdlog::info("MQTT: connected to the broker");
  connected_ = true;
  unreachable_said_ = false;
  publish(options_.prefix + "/availability", "online", 1, true);
  if (!state_.empty()) publish(options_.prefix + "/state", state_, 1, true);
  for (auto& pending : queue_)
    pending.mid = 0;
  send_queue();
}

void MqttPublisher::on_disconnect(int rc) {
  if (connected_) {
    spdlog::warn("MQTT: the broker's connection is lost; trying again");
  } else {
    unreachable(mosquitto_strerror(rc));
  }
  connected_ = false;
}

void MqttPublisher::on_error(const std::string& words) {
  if (!connected_) unreachable(words);
}

void MqttPublisher::unreachable(const std::string& why) {
  // Once an outage, not at every try.
  if (unreachable_said_) return;
  unreachable_said_ = true;
  spdlog::warn("MQTT: cannot reach the broker: {}; trying again", why);
}

void MqttPublisher::on_publish(int mid) {
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if (it->mid == mid) {
      queue_.erase(it);
      return;
    }
  }
}

void MqttPublisher::stop() {
  if (!started_) return;
  if (connected_) publish(options_.prefix + "/availability", "offline", 1, true);
  // MQTT 5 can say so: the broker then publishes the will as well, should the "offline"
  // above not have gone out before the disconnect.
  if (options_.broker.protocol == 5) {
    mosquitto_disconnect_v5(mosq_, 4, nullptr);
  } else {
    mosquitto_disconnect(mosq_);
  }
  mosquitto_loop_stop(mosq_, false);
  started_ = false;
  connected_ = false;
}

}  // namespace cncd::telemetry
