// cncd-telemetry's parts wired together on one io_context: the feed from cncd, /metrics, the
// SHDR adapter and the MQTT publisher (each only when configured).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "cncd/config/machine_config.hpp"
#include "machine_feed.hpp"
#include "metrics.hpp"
#include "metrics_server.hpp"
#include "mqtt.hpp"
#include "shdr.hpp"

namespace cncd::telemetry {

struct Endpoints {
  std::string metrics_address;
  int metrics_port = 0;  // 0 and not forced: none
  bool metrics_forced = false;
  std::string shdr_address;
  int shdr_port = 0;
  bool shdr_forced = false;
};

class App {
 public:
  App(boost::asio::io_context& io, const config::TelemetryConfig& config, std::string socket_path,
      std::vector<char> axes);
  // Listens and connects; "" or what went wrong.
  std::string start(const Endpoints& endpoints);
  void stop();

 private:
  void on_status();
  void on_event(const nlohmann::json& event);
  void on_jobs();
  void publish_state();
  void tick_position();

  boost::asio::io_context& io_;
  const config::TelemetryConfig& config_;
  Counters counters_;
  MachineFeed feed_;
  MetricsServer metrics_;
  ShdrServer shdr_;
  bool shdr_on_ = false;
  std::unique_ptr<MqttPublisher> mqtt_;
  boost::asio::steady_timer position_timer_;
  nlohmann::json last_state_;
  nlohmann::json last_error_;
  // The job rows already told: none before the first answer, so a restart tells no old one.
  long long jobs_told_ = -1;
};

}  // namespace cncd::telemetry
