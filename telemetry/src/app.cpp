#include "app.hpp"

#include <chrono>

#include <spdlog/spdlog.h>

#include "json_read.hpp"
#include "payloads.hpp"

namespace cncd::telemetry {

using nlohmann::json;

App::App(boost::asio::io_context& io, const config::TelemetryConfig& config,
         std::string socket_path, std::vector<char> axes)
    : io_(io),
      config_(config),
      feed_(io, std::move(socket_path),
            {[this] { on_status(); }, [this](const json& event) { on_event(event); },
             [this] { on_jobs(); }, [this](bool) { on_status(); }}),
      metrics_(io,
               [this] {
                 if (mqtt_) {
                   counters_.mqtt = true;
                   counters_.mqtt_connected = mqtt_->connected();
                   counters_.mqtt_queued = mqtt_->queued();
                   counters_.mqtt_dropped = mqtt_->dropped();
                 }
                 return prometheus_text(feed_, counters_, config_.machine_id);
               }),
      shdr_(io, feed_, std::move(axes)),
      position_timer_(io) {}

std::string App::start(const Endpoints& e) {
  if (e.metrics_port != 0 || e.metrics_forced) {
    if (const auto error = metrics_.listen(e.metrics_address, e.metrics_port); !error.empty())
      return "/metrics: " + error;
    spdlog::info("serving /metrics on {}:{}", e.metrics_address, metrics_.port());
  }
  if (e.shdr_port != 0 || e.shdr_forced) {
    if (const auto error = shdr_.listen(e.shdr_address, e.shdr_port); !error.empty())
      return "SHDR adapter: " + error;
    shdr_on_ = true;
    spdlog::info("serving SHDR on {}:{}", e.shdr_address, shdr_.port());
  }
  if (!config_.mqtt_host.empty()) {
    MqttOptions options;
    options.broker = broker_options(config_);
    options.prefix = config_.topic_prefix;
    options.queue = static_cast<std::size_t>(config_.event_queue);
    mqtt_ = std::make_unique<MqttPublisher>(io_, options);
    if (const auto error = mqtt_->start(); !error.empty()) return error;
    spdlog::info("MQTT: publishing under {}/", config_.topic_prefix);
    publish_state();
    if (config_.position_hz > 0) tick_position();
  }
  feed_.start();
  return "";
}

void App::stop() {
  feed_.stop();
  metrics_.stop();
  shdr_.stop();
  position_timer_.cancel();
  if (mqtt_) mqtt_->stop();
}

void App::on_status() {
  if (shdr_on_) shdr_.changed();
  publish_state();
}

// Only when something in it changed: a position moving is not a new state.
void App::publish_state() {
  if (!mqtt_) return;
  json state = state_payload(feed_, config_.machine_id, last_error_, config_.dashboard_url);
  if (state == last_state_) return;
  last_state_ = state;
  state["time"] = unix_time();
  mqtt_->state(state);
}

void App::on_event(const json& event) {
  ++counters_.events[{text_at(event, "level"), text_at(event, "kind")}];
  if (text_at(event, "kind") == "fault") {
    const std::string code = text_at(event, "code");
    ++counters_.faults[code.empty() ? "other" : code];
  }
  if (text_at(event, "level") == "error") {
    last_error_ = {{"seq", count_at(event, "seq")},
                   {"time", number_at(event, "time")},
                   {"kind", text_at(event, "kind")},
                   {"message", text_at(event, "message")}};
    publish_state();
  }
  if (mqtt_) mqtt_->event(with_machine(event, config_.machine_id));
}

void App::on_jobs() {
  if (shdr_on_) shdr_.changed();
  publish_state();  // the part count
  const json& job = feed_.last_job();
  const bool known = job.is_object() && job.contains("id");
  if (jobs_told_ < 0) {
    // The first answers: what ended before this process started is not news.
    if (known) {
      const auto id = static_cast<long long>(number_at(job, "id"));
      jobs_told_ = text_at(job, "result") != "running" ? id : id - 1;
    } else if (feed_.jobs().contains("jobs") && number_at(feed_.jobs(), "jobs") == 0) {
      jobs_told_ = 0;  // an empty history
    }
    return;
  }
  if (!known || text_at(job, "result") == "running") return;
  const auto id = static_cast<long long>(number_at(job, "id"));
  if (id <= jobs_told_) return;
  jobs_told_ = id;
  if (mqtt_) mqtt_->job(with_machine(job, config_.machine_id));
}

void App::tick_position() {
  if (mqtt_ && feed_.connected() && feed_.status().contains("position"))
    mqtt_->position(position_payload(feed_, config_.machine_id));
  position_timer_.expires_after(
      std::chrono::microseconds(static_cast<long long>(1e6 / config_.position_hz)));
  position_timer_.async_wait([this](boost::system::error_code ec) {
    if (!ec) tick_position();
  });
}

}  // namespace cncd::telemetry
