#include "listener.hpp"

#include <spdlog/spdlog.h>

#include "http_session.hpp"

namespace cncd::web {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

Listener::Listener(App& app)
    : app_(app),
      loop_(app.io,
            tcp::endpoint(asio::ip::make_address(app.web.listen),
                          static_cast<unsigned short>(app.web.port)),
            [this](tcp::socket socket) { on_socket(std::move(socket)); }) {}

void Listener::on_socket(tcp::socket socket) {
  const std::size_t limit = app_.limits.max_connections != 0
                                ? app_.limits.max_connections
                                : 4 * static_cast<std::size_t>(app_.web.max_clients) + 16;
  boost::system::error_code peer_ec;
  const auto remote = socket.remote_endpoint(peer_ec);
  Peer peer{peer_ec ? std::string("?") : remote.address().to_string(), app_.tls.has_value()};
  if (app_.connections >= limit) {
    spdlog::warn("connection from {} refused: {} connections open", peer.address, app_.connections);
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
}

}  // namespace cncd::web
