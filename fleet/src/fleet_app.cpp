#include "fleet_app.hpp"

#include <chrono>
#include <vector>

#include "http_common.hpp"

namespace cncd::fleet {

using nlohmann::json;

double unix_now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

namespace {

// Invalid UTF-8 from a machine becomes U+FFFD rather than an exception.
std::string dump(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace

FleetApp::FleetApp(boost::asio::io_context& io_context, Options opts)
    : io(io_context),
      options(std::move(opts)),
      table_(options.pattern, options.limits),
      push_timer_(io_context) {}

void FleetApp::on_message(const std::string& topic, const std::string& payload) {
  if (table_.apply(topic, payload, unix_now()) == MachineTable::Outcome::changed) schedule_push();
}

void FleetApp::on_too_large(const std::string& topic, std::size_t bytes) {
  table_.refuse(MachineTable::Refusal::too_large, topic, bytes);
}

void FleetApp::on_broker(bool connected) {
  if (connected == broker_connected_) return;
  broker_connected_ = connected;
  for (auto* viewer : viewers_)
    viewer->send(dump({{"type", "broker"}, {"connected", connected}}));
}

json FleetApp::snapshot() const {
  return {{"type", "snapshot"},
          {"broker", {{"connected", broker_connected_}}},
          {"ignored", table_.refused_total()},
          {"machines", table_.rows()}};
}

void FleetApp::add(Viewer* viewer) {
  viewers_.insert(viewer);
  viewer->send(dump(snapshot()));
}

void FleetApp::remove(Viewer* viewer) {
  viewers_.erase(viewer);
}

void FleetApp::close_all(const std::string& reason) {
  for (auto* viewer : std::vector<Viewer*>(viewers_.begin(), viewers_.end()))
    viewer->close_with(reason);
}

void FleetApp::schedule_push() {
  if (push_pending_) return;
  push_pending_ = true;
  push_timer_.expires_after(std::chrono::milliseconds(options.push_ms));
  push_timer_.async_wait([this](boost::system::error_code ec) {
    push_pending_ = false;
    if (!ec) push();
  });
}

// One frame with every row changed since the last: the latest of each, however often it
// changed meanwhile.
void FleetApp::push() {
  json machines = json::array();
  json removed = json::array();
  for (const auto& id : table_.take_changed()) {
    if (table_.has(id)) {
      machines.push_back(table_.row(id));
    } else {
      removed.push_back(id);
    }
  }
  if (viewers_.empty() || (machines.empty() && removed.empty())) return;
  const std::string frame = dump({{"type", "update"},
                                  {"time", unix_now()},
                                  {"ignored", table_.refused_total()},
                                  {"machines", std::move(machines)},
                                  {"removed", std::move(removed)}});
  for (auto* viewer : std::vector<Viewer*>(viewers_.begin(), viewers_.end()))
    viewer->send(frame);
}

bool FleetApp::origin_allowed(std::string_view origin, std::string_view host) const {
  return web::origin_allowed(origin, host, false, options.allowed_origins);
}

}  // namespace cncd::fleet
