// The status object, built at most once per turn of the server and shared by every status.get
// answer and status update of that turn. A command served marks it stale, so that a status
// asked for after a command's answer shows what the command did.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

namespace cncd::daemon {

class StatusCache {
 public:
  explicit StatusCache(std::function<nlohmann::json()> build) : build_(std::move(build)) {}
  const nlohmann::json& get() { return *snapshot(); }
  // The status of this turn, kept unchanged for as long as someone holds it: status updates
  // compare against the snapshot a client last saw without copying it.
  const std::shared_ptr<const nlohmann::json>& snapshot() {
    if (!fresh_) {
      status_ = std::make_shared<const nlohmann::json>(build_());
      fresh_ = true;
    }
    return status_;
  }
  // The status serialized, as a status.get answer carries it.
  const std::string& text() {
    if (!text_fresh_) {
      text_ = get().dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      text_fresh_ = true;
    }
    return text_;
  }
  void invalidate() { fresh_ = text_fresh_ = false; }

 private:
  std::function<nlohmann::json()> build_;
  std::shared_ptr<const nlohmann::json> status_;
  std::string text_;
  bool fresh_ = false;
  bool text_fresh_ = false;
};

}  // namespace cncd::daemon
