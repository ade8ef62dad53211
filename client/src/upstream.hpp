// One connection to cncd's control socket: newline-delimited JSON-RPC, as cncctl speaks it.
// cncd-web gives each WebSocket its own, so its subscriptions and request ids stay the
// client's own; cncd-telemetry holds one.
#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/streambuf.hpp>

namespace cncd::client {

class Upstream : public std::enable_shared_from_this<Upstream> {
 public:
  using LineHandler = std::function<void(std::string line)>;
  using CloseHandler = std::function<void(const std::string& why)>;

  // `max_line`: the longest line accepted from cncd (a preview's answer is one line).
  Upstream(boost::asio::io_context& io, std::string socket_path, std::size_t max_line);
  // Connects and reads; `on_line` gets each line without its newline, `on_close` is called
  // once when the connection ends for a reason other than close().
  void start(LineHandler on_line, CloseHandler on_close);
  // Queues `line` (without newline); lines sent before the connection is up wait for it.
  void send(std::string line);
  // Sends what is queued, then closes: a WebSocket's last jog.stop still reaches cncd.
  void close_after_sending();
  void close();
  // Bytes queued towards cncd and not yet written.
  std::size_t queued_bytes() const { return queued_bytes_; }

 private:
  void read_next();
  void write_next();
  void fail(const std::string& why);

  boost::asio::local::stream_protocol::socket socket_;
  std::string path_;
  boost::asio::streambuf in_;
  std::deque<std::string> out_;
  std::size_t queued_bytes_ = 0;
  bool connected_ = false;
  bool writing_ = false;
  bool closing_ = false;
  bool closed_ = false;
  LineHandler on_line_;
  CloseHandler on_close_;
};

}  // namespace cncd::client
