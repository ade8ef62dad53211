// What cncd's MQTT clients (cncd-telemetry's publisher, cncd-fleet's subscriber) share: the
// broker's address, credentials and TLS as [TELEMETRY] gives them, and a libmosquitto client
// set up for them. Neither the address nor the credentials are ever logged.
#pragma once

#include <string>

#include "cncd/config/machine_config.hpp"

struct mosquitto;

namespace cncd::telemetry {

struct BrokerOptions {
  std::string host;  // empty: no MQTT
  int port = 1883;
  std::string username;
  std::string password;
  std::string tls_ca;  // a CA file: TLS; empty: plain TCP
  int protocol = 5;    // 5 or 311
};

// [TELEMETRY] MQTT_HOST, MQTT_PORT, MQTT_USERNAME, MQTT_PASSWORD, MQTT_TLS_CA, MQTT_PROTOCOL.
BrokerOptions broker_options(const config::TelemetryConfig& config);

// A client with the protocol, credentials, TLS and reconnection backoff (1 s doubling to 60 s)
// of `options`, `self` handed to its callbacks; nullptr and `error` set when it cannot be made.
mosquitto* new_client(const BrokerOptions& options, void* self, std::string& error);
// Connects in the background (a broker not there yet is tried again) on libmosquitto's own
// thread; "" or what is wrong with the options. `unreachable` says why the first try failed
// ("" when it has not, yet).
std::string connect_in_background(mosquitto* client, const BrokerOptions& options,
                                  std::string& unreachable);

}  // namespace cncd::telemetry
