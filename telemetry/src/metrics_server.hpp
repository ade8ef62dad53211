// GET /metrics over HTTP/1.1 (Boost.Beast) for Prometheus' scrapes. Anything else is 404 or
// 405; a connection that sends nothing for 30 s, a header over 8 KiB or a body is dropped, and
// at most 32 connections are served at once, so a scanner on the shop network costs little.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

namespace cncd::telemetry {

class MetricsServer {
 public:
  static constexpr std::size_t kMaxConnections = 32;

  MetricsServer(boost::asio::io_context& io, std::function<std::string()> render);
  // Listens on address:port (port 0: a free one, see port()); "" or what went wrong.
  std::string listen(const std::string& address, int port);
  int port() const;
  void stop();

 private:
  class Session;
  void accept();

  boost::asio::io_context& io_;
  boost::asio::ip::tcp::acceptor acceptor_;
  std::function<std::string()> render_;
  std::shared_ptr<std::size_t> open_ = std::make_shared<std::size_t>(0);
};

}  // namespace cncd::telemetry
