// cncd-fleet's shared state on its one I/O thread: the machine table the subscriber fills,
// the browsers' WebSockets, and the push of the table's changes to them at most every
// Options::push_ms (many machines changing at once make one frame, not one each).
#pragma once

#include <cstddef>
#include <set>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>
#include <nlohmann/json.hpp>

#include "machine_table.hpp"
#include "options.hpp"

namespace cncd::fleet {

// A browser's WebSocket as the app sees it.
class Viewer {
 public:
  virtual ~Viewer() = default;
  virtual void send(std::string frame) = 0;
  virtual void close_with(const std::string& reason) = 0;
};

class FleetApp {
 public:
  FleetApp(boost::asio::io_context& io, Options options);

  // A message from the broker.
  void on_message(const std::string& topic, const std::string& payload);
  void on_too_large(const std::string& topic, std::size_t bytes);
  void on_broker(bool connected);

  // {"type": "snapshot", "broker": ..., "machines": [...]}: a new viewer's first frame and
  // GET /api/machines.
  nlohmann::json snapshot() const;
  void add(Viewer* viewer);
  void remove(Viewer* viewer);
  void close_all(const std::string& reason);

  // The page's own origin ("http://" + Host), none, or one of --allowed-origin.
  bool origin_allowed(std::string_view origin, std::string_view host) const;

  boost::asio::io_context& io;
  const Options options;
  std::size_t connections = 0;  // HTTP and WebSocket connections open
  std::size_t viewers() const { return viewers_.size(); }

 private:
  void schedule_push();
  void push();

  MachineTable table_;
  std::set<Viewer*> viewers_;
  boost::asio::steady_timer push_timer_;
  bool push_pending_ = false;
  bool broker_connected_ = false;
};

double unix_now();

}  // namespace cncd::fleet
