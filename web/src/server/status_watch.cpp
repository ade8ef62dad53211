#include "status_watch.hpp"

#include <spdlog/spdlog.h>

namespace cncd::web {

void StatusWatch::start() {
  if (stopped_) return;
  status_ = nlohmann::json::object();
  upstream_ = std::make_shared<client::Upstream>(app_.io, app_.socket_path, 1 << 20);
  upstream_->start([this](std::string line) { on_line(line); },
                   [this](const std::string& why) {
                     app_.program_running = false;
                     app_.manual_holder = nullptr;
                     // Once per outage, not every 2 s while cncd is away.
                     if (!away_) spdlog::warn("{}; trying again every 2 s", why);
                     away_ = true;
                     retry_.expires_after(std::chrono::seconds(2));
                     retry_.async_wait([this](boost::system::error_code ec) {
                       if (!ec) start();
                     });
                   });
  upstream_->send(nlohmann::json{
      {"jsonrpc", "2.0"},
      {"id", 1},
      {"method", "status.subscribe"},
      {"params", {{"interval_ms", 200}, {"fields", {"program", "exec", "manual_holder"}}}}}
                      .dump());
}

void StatusWatch::stop() {
  stopped_ = true;
  retry_.cancel();
  if (upstream_) upstream_->close();
}

void StatusWatch::on_line(const std::string& line) {
  const auto message = nlohmann::json::parse(line, nullptr, false);
  if (away_) spdlog::info("connected to cncd at {}", app_.socket_path);
  away_ = false;
  if (!message.is_object() || message.value("method", "") != "status.update") return;
  const auto& params = message["params"];
  if (!params.is_object() || !params.value("changed", nlohmann::json()).is_object()) return;
  if (params.value("full", false)) status_ = nlohmann::json::object();
  status_.merge_patch(params["changed"]);
  const auto& program = status_.value("program", nlohmann::json::object());
  app_.open_program = program.is_object() && program.value("path", nlohmann::json()).is_string()
                          ? std::filesystem::path(program["path"].get<std::string>())
                          : std::filesystem::path();
  app_.program_running = status_.value("exec", "idle") != "idle";
  app_.manual_holder = status_.value("manual_holder", nlohmann::json());
}

}  // namespace cncd::web
