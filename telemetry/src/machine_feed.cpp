#include "machine_feed.hpp"

#include "json_read.hpp"

#include <spdlog/spdlog.h>

#include <utility>

namespace cncd::telemetry {

using nlohmann::json;

namespace {

// Request ids: one of each kind is ever outstanding, so the id says what answered.
constexpr int kSubscribe = 1;
constexpr int kErrors = 2;
constexpr int kJobs = 3;
constexpr int kLastJob = 4;
constexpr int kInfo = 5;

}  // namespace

MachineFeed::MachineFeed(boost::asio::io_context& io, std::string socket_path, Listener listener)
    : io_(io),
      socket_path_(std::move(socket_path)),
      listener_(std::move(listener)),
      retry_(io),
      jobs_timer_(io) {}

void MachineFeed::start() {
  connect();
}

void MachineFeed::stop() {
  stopped_ = true;
  retry_.cancel();
  jobs_timer_.cancel();
  if (upstream_) upstream_->close();
}

void MachineFeed::connect() {
  if (stopped_) return;
  caught_up_ = false;
  upstream_ = std::make_shared<client::Upstream>(io_, socket_path_, 1 << 20);
  upstream_->start([this](std::string line) { on_line(line); },
                   [this](const std::string& why) {
                     if (!away_logged_) spdlog::warn("{}; trying again every 2 s", why);
                     away_logged_ = true;
                     const bool was = connected_;
                     connected_ = false;
                     jobs_timer_.cancel();
                     if (was && listener_.connection) listener_.connection(false);
                     retry_.expires_after(std::chrono::seconds(2));
                     retry_.async_wait([this](boost::system::error_code ec) {
                       if (!ec) connect();
                     });
                   });
  ask("system.info", json::object(), kInfo);
  ask("status.subscribe", {{"interval_ms", 100}}, kSubscribe);
  ask("errors.list", {{"since", 0}}, kErrors);
  ask_jobs();
}

void MachineFeed::ask(const char* method, const json& params, int id) {
  upstream_->send(json{{"jsonrpc", "2.0"}, {"id", id}, {"method", method}, {"params", params}}.dump(
      -1, ' ', false, json::error_handler_t::replace));
}

void MachineFeed::ask_jobs() {
  ask("jobs.stats", json::object(), kJobs);
  ask("jobs.history", {{"limit", 1}}, kLastJob);
}

// The totals again every 10 s, besides at each run's end.
void MachineFeed::schedule_jobs() {
  jobs_timer_.expires_after(std::chrono::seconds(10));
  jobs_timer_.async_wait([this](boost::system::error_code ec) {
    if (ec || !connected_) return;
    ask_jobs();
    schedule_jobs();
  });
}

void MachineFeed::on_line(const std::string& line) {
  // What cncd sends is trusted for its shape no further than json_read.hpp allows; anything
  // else that throws costs that one line, never the process.
  try {
    handle(line);
  } catch (const std::exception& e) {
    spdlog::warn("a line from cncd left unread: {}", e.what());
  }
}

void MachineFeed::handle(const std::string& line) {
  const json message = json::parse(line, nullptr, false);
  if (!message.is_object()) return;
  if (!connected_) {
    if (away_logged_) spdlog::info("connected to cncd at {}", socket_path_);
    away_logged_ = false;
    connected_ = true;
    schedule_jobs();
    if (listener_.connection) listener_.connection(true);
  }
  const std::string method = text_at(message, "method");
  if (method == "status.update" && message["params"].is_object()) {
    on_status(message["params"]);
    return;
  }
  if (method == "event" && message["params"].is_object()) {
    // Before errors.list has answered, its answer holds this one too.
    if (caught_up_) on_event(message["params"]);
    return;
  }
  const json& result = message.contains("result") ? message["result"] : json::object();
  switch (static_cast<int>(number_at(message, "id"))) {
    case kInfo:
      if (result.is_object()) info_ = result;
      break;
    case kErrors: {
      if (!result.is_object()) break;
      // cncd started again: its numbers start again too.
      if (count_at(result, "last_seq") < last_seq_) last_seq_ = 0;
      for (const auto& event : array_at(result, "events"))
        on_event(event);
      caught_up_ = true;
      break;
    }
    case kJobs:
      jobs_ = result.is_object() ? result : json::object();
      if (listener_.jobs) listener_.jobs();
      break;
    case kLastJob:
      if (!array_at(result, "jobs").empty() && result["jobs"][0].is_object())
        last_job_ = result["jobs"][0];
      if (listener_.jobs) listener_.jobs();
      break;
    default:
      break;
  }
}

void MachineFeed::on_status(const json& params) {
  if (!params.contains("changed") || !params["changed"].is_object()) return;
  const json& changed = params["changed"];
  const auto now = std::chrono::steady_clock::now();
  // The spindle turned from the last update to this one if it turned at the last.
  if (last_update_ != std::chrono::steady_clock::time_point{} &&
      number_at(object_at(status_, "spindle"), "actual_rpm") != 0.0) {
    spindle_run_s_ += std::chrono::duration<double>(now - last_update_).count();
  }
  last_update_ = now;
  const std::string exec_before = text_at(status_, "exec");
  if (flag_at(params, "full")) status_ = json::object();
  status_.merge_patch(changed);
  // A run ended: its row and the totals have changed.
  if (exec_before != "idle" && !exec_before.empty() && text_at(status_, "exec") == "idle")
    ask_jobs();
  if (listener_.status) listener_.status();
}

void MachineFeed::on_event(const json& event) {
  const auto seq = count_at(event, "seq");
  if (seq <= last_seq_) return;
  last_seq_ = seq;
  if (listener_.event) listener_.event(event);
}

}  // namespace cncd::telemetry
