// Accepts TCP connections on one endpoint and hands each socket on; when accept fails (out of
// descriptors, most likely) it waits 100 ms rather than spin until some close.
#pragma once

#include <functional>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

namespace cncd::web {

class AcceptLoop {
 public:
  using Handler = std::function<void(boost::asio::ip::tcp::socket)>;
  // Binds; throws boost::system::system_error naming the address when it cannot.
  AcceptLoop(boost::asio::io_context& io, const boost::asio::ip::tcp::endpoint& where,
             Handler handler);
  void start();
  void stop();
  boost::asio::ip::tcp::endpoint endpoint() const { return acceptor_.local_endpoint(); }

 private:
  void accept_next();

  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer retry_;
  Handler handler_;
};

}  // namespace cncd::web
