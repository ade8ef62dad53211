// cncd-web's own subscription to cncd's status: which program is open and whether it runs,
// so that uploads, renames and deletes never touch the running program. Reconnects while
// cncd is away.
#pragma once

#include <memory>

#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "app.hpp"
#include "upstream.hpp"

namespace cncd::web {

class StatusWatch {
 public:
  explicit StatusWatch(App& app) : app_(app), retry_(app.io) {}
  void start();
  void stop();

 private:
  void on_line(const std::string& line);

  App& app_;
  std::shared_ptr<client::Upstream> upstream_;
  boost::asio::steady_timer retry_;
  nlohmann::json status_;
  bool stopped_ = false;
  bool away_ = false;  // cncd could not be reached last time
};

}  // namespace cncd::web
