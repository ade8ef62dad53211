// The MTConnect adapter: SHDR over TCP ([TELEMETRY] SHDR_LISTEN, SHDR_PORT) for an MTConnect
// agent (cppagent) to connect to. Each agent gets every data item when it connects, then the
// items that changed, at most 10 times a second; "* PING" is answered "* PONG 10000".
// docs/telemetry.md maps each item to its MTConnect type; devices_xml() describes them.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "machine_feed.hpp"

namespace cncd::telemetry {

// Data item key -> SHDR value, as the feed has them now ("UNAVAILABLE" where unknown).
// Conditions are kept apart: SHDR gives each its own line.
struct ShdrItems {
  std::map<std::string, std::string> samples;
  std::map<std::string, std::string> conditions;  // key -> "NORMAL||||" or "FAULT||||text"
};
ShdrItems shdr_items(const MachineFeed& feed, const std::vector<char>& axes);
// "2026-11-29T01:38:00.123Z"
std::string shdr_time();
// The lines that carry `now` where it differs from `before` (all of `now` when `before` is
// empty), each ending in '\n'.
std::string shdr_lines(const ShdrItems& before, const ShdrItems& now, const std::string& time);
// The MTConnect Devices.xml that names the items (for the agent's configuration).
std::string devices_xml(const std::string& machine_id, const std::string& machine_name,
                        const std::vector<char>& axes);

class ShdrServer {
 public:
  static constexpr std::size_t kMaxAgents = 8;

  ShdrServer(boost::asio::io_context& io, const MachineFeed& feed, std::vector<char> axes);
  std::string listen(const std::string& address, int port);
  int port() const;
  // The feed changed: sends what changed, now or at the next 100 ms.
  void changed();
  void stop();

 private:
  class Agent;
  void accept();
  void flush();

  boost::asio::io_context& io_;
  const MachineFeed& feed_;
  std::vector<char> axes_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer throttle_;
  bool pending_ = false;
  bool waiting_ = false;
  ShdrItems sent_;
  std::set<std::shared_ptr<Agent>> agents_;
};

}  // namespace cncd::telemetry
