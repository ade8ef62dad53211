#include "mqtt_client.hpp"

#include <mosquitto.h>

namespace cncd::telemetry {

BrokerOptions broker_options(const config::TelemetryConfig& config) {
  return {config.mqtt_host,
          config.mqtt_port,
          config.mqtt_username,
          config.mqtt_password,
          config.mqtt_tls_ca.string(),
          config.mqtt_protocol};
}

mosquitto* new_client(const BrokerOptions& options, void* self, std::string& error) {
  static const int init = mosquitto_lib_init();
  if (init != MOSQ_ERR_SUCCESS) {
    error = "libmosquitto: " + std::string(mosquitto_strerror(init));
    return nullptr;
  }
  mosquitto* client = mosquitto_new(nullptr, true, self);
  if (client == nullptr) {
    error = "libmosquitto: cannot make a client";
    return nullptr;
  }
  mosquitto_int_option(client, MOSQ_OPT_PROTOCOL_VERSION,
                       options.protocol == 5 ? MQTT_PROTOCOL_V5 : MQTT_PROTOCOL_V311);
  if (!options.username.empty() &&
      mosquitto_username_pw_set(client, options.username.c_str(),
                                options.password.empty() ? nullptr : options.password.c_str()) !=
          MOSQ_ERR_SUCCESS) {
    error = "MQTT: the user name or password is not valid";
  } else if (!options.tls_ca.empty()) {
    if (const int rc =
            mosquitto_tls_set(client, options.tls_ca.c_str(), nullptr, nullptr, nullptr, nullptr);
        rc != MOSQ_ERR_SUCCESS) {
      error = "MQTT: cannot use the CA file " + options.tls_ca + ": " + mosquitto_strerror(rc);
    }
  }
  if (!error.empty()) {
    mosquitto_destroy(client);
    return nullptr;
  }
  mosquitto_reconnect_delay_set(client, 1, 60, true);
  return client;
}

std::string connect_in_background(mosquitto* client, const BrokerOptions& options,
                                  std::string& unreachable) {
  // Only options that can never work fail here. A broker that is not there yet, a name that
  // does not resolve yet, a certificate the CA did not sign: all tried again by the loop, as
  // when they happen later.
  const int rc = mosquitto_connect_async(client, options.host.c_str(), options.port, 30);
  if (rc == MOSQ_ERR_INVAL || rc == MOSQ_ERR_NOMEM || rc == MOSQ_ERR_NOT_SUPPORTED)
    return std::string("MQTT: cannot connect: ") + mosquitto_strerror(rc);
  unreachable = rc == MOSQ_ERR_SUCCESS ? "" : mosquitto_strerror(rc);
  if (const int loop = mosquitto_loop_start(client); loop != MOSQ_ERR_SUCCESS)
    return std::string("MQTT: ") + mosquitto_strerror(loop);
  return "";
}

}  // namespace cncd::telemetry
