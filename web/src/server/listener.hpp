// Accepts connections on [WEB] LISTEN:PORT and starts a plain or TLS HTTP session for each,
// refusing beyond the connection limit.
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "app.hpp"

namespace cncd::web {

class Listener {
 public:
  // Binds; throws boost::system::system_error naming the address when it cannot.
  explicit Listener(App& app);
  void start();
  void stop();
  boost::asio::ip::tcp::endpoint endpoint() const { return acceptor_.local_endpoint(); }

 private:
  void accept_next();

  App& app_;
  boost::asio::ip::tcp::acceptor acceptor_;
  boost::asio::steady_timer retry_;
};

}  // namespace cncd::web
