#include "listener.hpp"

#include <spdlog/spdlog.h>

#include "http_session.hpp"

namespace cncd::web {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

Listener::Listener(App& app) : app_(app), acceptor_(app.io), retry_(app.io) {
  const tcp::endpoint where(asio::ip::make_address(app.web.listen),
                            static_cast<unsigned short>(app.web.port));
  acceptor_.open(where.protocol());
  acceptor_.set_option(asio::socket_base::reuse_address(true));
  acceptor_.bind(where);
  acceptor_.listen(asio::socket_base::max_listen_connections);
}

void Listener::start() {
  accept_next();
}

void Listener::stop() {
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  retry_.cancel();
}

void Listener::accept_next() {
  acceptor_.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;
    if (!ec) {
      const std::size_t limit = app_.limits.max_connections != 0
                                    ? app_.limits.max_connections
                                    : 4 * static_cast<std::size_t>(app_.web.max_clients) + 16;
      boost::system::error_code peer_ec;
      const auto remote = socket.remote_endpoint(peer_ec);
      Peer peer{peer_ec ? std::string("?") : remote.address().to_string(), app_.tls.has_value()};
      // Answers are small frames: without this an estop's answer waits for the client's
      // delayed ACK (about 40 ms) behind the status update sent before it.
      boost::system::error_code nodelay_ec;
      socket.set_option(tcp::no_delay(true), nodelay_ec);
      if (app_.connections >= limit) {
        spdlog::warn("connection from {} refused: {} connections open", peer.address,
                     app_.connections);
      } else if (app_.tls) {
        using TlsStream = beast::ssl_stream<beast::tcp_stream>;
        std::make_shared<HttpSession<TlsStream>>(
            app_, TlsStream(beast::tcp_stream(std::move(socket)), *app_.tls), std::move(peer))
            ->run();
      } else {
        std::make_shared<HttpSession<beast::tcp_stream>>(app_, beast::tcp_stream(std::move(socket)),
                                                         std::move(peer))
            ->run();
      }
    } else {
      // Out of descriptors, most likely: wait rather than spin until some close.
      spdlog::warn("accept: {}; pausing 100 ms", ec.message());
      retry_.expires_after(std::chrono::milliseconds(100));
      return retry_.async_wait([this](boost::system::error_code wait_ec) {
        if (!wait_ec) accept_next();
      });
    }
    accept_next();
  });
}

}  // namespace cncd::web
