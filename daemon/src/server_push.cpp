// What the server sends unasked: status updates, events, and answers that come later.
#include <algorithm>
#include <memory>
#include <unordered_map>
#include <utility>

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

namespace {

std::string dump(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace

void Server::push_updates(Clock::time_point now) {
  // At most kUpdatesPerTurn updates a turn, from where the last turn's ended: the rest are
  // still due and go out in the next turns, after the stops read meanwhile.
  const std::size_t count = clients_.size();
  std::size_t sent = 0;
  std::size_t k = 0;
  // The changes since a snapshot, serialized once for every whole-status subscriber that last
  // saw that snapshot (clients served in one turn are mostly served together again).
  std::unordered_map<const nlohmann::json*,
                     std::pair<std::shared_ptr<const nlohmann::json>, std::string>>
      since;
  for (; k < count && sent < kUpdatesPerTurn; ++k) {
    Client& client = clients_[(next_update_client_ + k) % count];
    const int interval = client.session.subscribe_interval_ms;
    if (interval <= 0) {
      client.last_whole.reset();
      client.last_view = nullptr;
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
    const auto& status = status_.snapshot();
    bool full = false;
    std::string changed;
    if (client.session.fields.empty()) {
      client.last_view = nullptr;
      full = client.last_whole == nullptr;
      if (full) {
        changed = status_.text();
      } else if (client.last_whole != status) {
        auto [entry, added] = since.try_emplace(client.last_whole.get());
        if (added)
          entry->second = {client.last_whole, dump(merge_diff(*client.last_whole, *status))};
        changed = entry->second.second;
      }
      client.last_whole = status;
      if (changed.empty() || changed == "{}") continue;
    } else {
      client.last_whole.reset();
      nlohmann::json view = nlohmann::json::object();
      for (const auto& field : client.session.fields) {
        if (const auto it = status->find(field); it != status->end()) view[field] = *it;
      }
      full = client.last_view.is_null();
      const nlohmann::json diff = full ? view : merge_diff(client.last_view, view);
      if (diff.empty()) continue;
      changed = dump(diff);
      client.last_view = std::move(view);
    }
    const auto wall = std::chrono::system_clock::now().time_since_epoch();
    // {"jsonrpc","method","params":{"changed","full","seq","time"}}, as nlohmann orders keys.
    std::string& out = client.out;
    out += R"({"jsonrpc":"2.0","method":"status.update","params":{"changed":)";
    out += changed;
    out += full ? R"(,"full":true,"seq":)" : R"(,"full":false,"seq":)";
    out += std::to_string(++client.update_seq);
    out += R"(,"time":)";
    out += nlohmann::json(std::chrono::duration<double>(wall).count()).dump();
    out += "}}\n";
    client.last_update = now;
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
      if (client.closing) client.close_by = Clock::now() + kCloseGrace;
      if (done.error_code == 0 && done.raw_result) {
        const nlohmann::json id = std::move(it->second);
        open.erase(it);
        answer_raw(client, id, std::move(done.raw_result));
        write_client(client);
        break;
      }
      nlohmann::json response = {{"jsonrpc", "2.0"}, {"id", it->second}};
      if (done.error_code == 0) {
        response["result"] = std::move(done.result);
      } else {
        response["error"] = RpcDispatcher::error_object(done.error_code, done.error_message);
      }
      open.erase(it);
      client.out += response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      client.out += '\n';
      write_client(client);
      break;
    }
  }
}

void Server::answer_raw(Client& client, const nlohmann::json& id,
                        std::shared_ptr<const std::string> result) {
  if (client.out.size() > kMaxBacklogBytes) {
    client.held_bytes += result->size();
    client.held.emplace_back(id, std::move(result));
    if (client.held_bytes > kMaxHeldBytes) {
      cut_off(client, std::to_string(client.held_bytes) + " bytes of answers held",
              "client does not read its messages: answers held over 32 MiB");
    }
    return;
  }
  // {"id","jsonrpc","result"}, as nlohmann orders keys; the result is copied, not parsed.
  const std::size_t before = client.out.size();
  client.out += R"({"id":)";
  client.out += id.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  client.out += R"(,"jsonrpc":"2.0","result":)";
  client.out += *result;
  client.out += "}\n";
  // One such answer may wait beyond the backlog: the next is held until the client reads.
  client.asked_bytes = std::max(client.asked_bytes, client.out.size() - before);
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
