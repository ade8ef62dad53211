// cncd-telemetry's one connection to cncd: the status as a subscription merges it, every event
// in order (those missed while away fetched again with errors.list), and the job history's
// totals. Reconnects every 2 s while cncd is away. Read-only: it calls nothing that changes the
// machine, so [CNCD] READ_GROUP is all it needs.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "upstream.hpp"

namespace cncd::telemetry {

class MachineFeed {
 public:
  // What a consumer is told: the status changed (`status()`), an event came (in seq order,
  // none twice), the job totals were read again, or the connection came or went.
  struct Listener {
    std::function<void()> status;
    std::function<void(const nlohmann::json& event)> event;
    std::function<void()> jobs;
    std::function<void(bool connected)> connection;
  };

  MachineFeed(boost::asio::io_context& io, std::string socket_path, Listener listener);
  void start();
  void stop();

  bool connected() const { return connected_; }
  // The merged status (status.get's fields), {} before the first update.
  const nlohmann::json& status() const { return status_; }
  // system.info's answer, {} until it came.
  const nlohmann::json& info() const { return info_; }
  // jobs.stats' last answer, {} until one came (or while the history cannot be read).
  const nlohmann::json& jobs() const { return jobs_; }
  const nlohmann::json& last_job() const { return last_job_; }
  std::uint64_t last_seq() const { return last_seq_; }
  // Seconds the spindle turned while watched.
  double spindle_run_s() const { return spindle_run_s_; }

 private:
  void connect();
  void on_line(const std::string& line);
  void handle(const std::string& line);
  void on_status(const nlohmann::json& params);
  void on_event(const nlohmann::json& event);
  void ask(const char* method, const nlohmann::json& params, int id);
  void ask_jobs();
  void schedule_jobs();

  boost::asio::io_context& io_;
  std::string socket_path_;
  Listener listener_;
  std::shared_ptr<client::Upstream> upstream_;
  boost::asio::steady_timer retry_;
  boost::asio::steady_timer jobs_timer_;
  bool stopped_ = false;
  bool connected_ = false;
  bool away_logged_ = false;
  nlohmann::json status_ = nlohmann::json::object();
  nlohmann::json info_ = nlohmann::json::object();
  nlohmann::json jobs_ = nlohmann::json::object();
  nlohmann::json last_job_ = nlohmann::json::object();
  std::uint64_t last_seq_ = 0;
  bool caught_up_ = false;  // errors.list has answered since the connection came
  double spindle_run_s_ = 0;
  std::chrono::steady_clock::time_point last_update_{};
};

}  // namespace cncd::telemetry
