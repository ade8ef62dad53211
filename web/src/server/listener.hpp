// Accepts connections on [WEB] LISTEN:PORT and starts a plain or TLS HTTP session for each,
// refusing beyond the connection limit.
#pragma once

#include <boost/asio/ip/tcp.hpp>

#include "accept_loop.hpp"
#include "app.hpp"

namespace cncd::web {

class Listener {
 public:
  // Binds; throws boost::system::system_error naming the address when it cannot.
  explicit Listener(App& app);
  void start() { loop_.start(); }
  void stop() { loop_.stop(); }
  boost::asio::ip::tcp::endpoint endpoint() const { return loop_.endpoint(); }

 private:
  void on_socket(boost::asio::ip::tcp::socket socket);

  App& app_;
  AcceptLoop loop_;
};

}  // namespace cncd::web
