// What the server sends unasked: status updates, events, and answers that come later.
#include <algorithm>

#include "server.hpp"
#include "status_json.hpp"

namespace cncd::daemon {

nlohmann::json merge_diff(const nlohmann::json& before, const nlohmann::json& after) {
  if (!before.is_object() || !after.is_object()) return after;
  nlohmann::json patch = nlohmann::json::object();
  for (const auto& [key, value] : after.items()) {
    const auto old = before.find(key);
    if (old == before.end()) {
      patch[key] = value;
    } else if (*old != value) {
      patch[key] = value.is_object() && old->is_object() ? merge_diff(*old, value) : value;
    }
  }
  return patch;
}

int Server::next_update_in_ms(Clock::time_point now) const {
  int wait_ms = -1;
  for (const auto& client : clients_) {
    if (client.session.subscribe_interval_ms <= 0 || client.closing) continue;
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(client.next_update - now).count();
    const int ms = left < 0 ? 0 : static_cast<int>(left);
    wait_ms = wait_ms < 0 ? ms : std::min(wait_ms, ms);
  }
  return wait_ms;
}

void Server::push_updates(Clock::time_point now) {
  // At most kUpdatesPerTurn updates a turn, from where the last turn's ended: the rest are
  // still due and go out in the next turns, after the stops read meanwhile.
  const std::size_t count = clients_.size();
  std::size_t sent = 0;
  std::size_t k = 0;
  for (; k < count && sent < kUpdatesPerTurn; ++k) {
    Client& client = clients_[(next_update_client_ + k) % count];
    const int interval = client.session.subscribe_interval_ms;
    if (interval <= 0) {
      client.last_sent = nullptr;
      continue;
    }
    // Besides the periodic check, a request that may have changed the state is followed at
    // once by an update to every client whose interval has passed since its last one.
    const auto period = std::chrono::milliseconds(interval);
    const bool due =
        now >= client.next_update || (requests_handled_ && now - client.last_update >= period);
    if (client.closing || !due) continue;
    client.next_update = now + period;
    // A client still holding unsent output gets the changes coalesced into a later update.
    if (!client.out.empty()) continue;
    ++sent;
    const nlohmann::json& status = status_.get();
    nlohmann::json view;
    if (client.session.fields.empty()) {
      view = status;
    } else {
      view = nlohmann::json::object();
      for (const auto& field : client.session.fields) {
        if (const auto it = status.find(field); it != status.end()) view[field] = *it;
      }
    }
    nlohmann::json changed = client.last_sent.is_null() ? view : merge_diff(client.last_sent, view);
    if (changed.empty()) continue;
    const auto wall = std::chrono::system_clock::now().time_since_epoch();
    const nlohmann::json update = {{"jsonrpc", "2.0"},
                                   {"method", "status.update"},
                                   {"params",
                                    {{"seq", ++client.update_seq},
                                     {"time", std::chrono::duration<double>(wall).count()},
                                     {"full", client.last_sent.is_null()},
                                     {"changed", std::move(changed)}}}};
    client.last_sent = std::move(view);
    client.last_update = now;
    client.out += update.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    client.out += '\n';
    write_client(client);
  }
  next_update_client_ = count == 0 ? 0 : (next_update_client_ + k) % count;
}

void Server::deliver_completions() {
  for (auto& done : completions_.take()) {
    for (auto& client : clients_) {
      auto& open = client.session.open_requests;
      const auto it = std::find_if(open.begin(), open.end(),
                                   [&](const auto& entry) { return entry.first == done.token; });
      if (it == open.end()) continue;
      nlohmann::json response = {{"jsonrpc", "2.0"}, {"id", it->second}};
      if (done.error_code == 0) {
        response["result"] = std::move(done.result);
      } else {
        response["error"] = RpcDispatcher::error_object(done.error_code, done.error_message);
      }
      open.erase(it);
      if (client.closing) client.close_by = Clock::now() + kCloseGrace;
      client.out += response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      client.out += '\n';
      write_client(client);
      break;
    }
  }
}

void Server::push_events() {
  const std::uint64_t last = events_.last_seq();
  for (auto& client : clients_) {
    if (client.closing || client.event_seq >= last) continue;
    for (const auto& event : events_.since(client.event_seq)) {
      const nlohmann::json note = {
          {"jsonrpc", "2.0"}, {"method", "event"}, {"params", event_json(event)}};
      client.out += note.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      client.out += '\n';
    }
    client.event_seq = last;
    write_client(client);
  }
}

}  // namespace cncd::daemon
