#include "accept_loop.hpp"

#include <spdlog/spdlog.h>

namespace cncd::web {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

AcceptLoop::AcceptLoop(asio::io_context& io, const tcp::endpoint& where, Handler handler)
    : acceptor_(io), retry_(io), handler_(std::move(handler)) {
  acceptor_.open(where.protocol());
  acceptor_.set_option(asio::socket_base::reuse_address(true));
  acceptor_.bind(where);
  acceptor_.listen(asio::socket_base::max_listen_connections);
}

void AcceptLoop::start() {
  accept_next();
}

void AcceptLoop::stop() {
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  retry_.cancel();
}

void AcceptLoop::accept_next() {
  acceptor_.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {
      spdlog::warn("accept: {}; pausing 100 ms", ec.message());
      retry_.expires_after(std::chrono::milliseconds(100));
      return retry_.async_wait([this](boost::system::error_code wait_ec) {
        if (!wait_ec) accept_next();
      });
    }
    // Answers are small frames: without this one waits for the client's delayed ACK (about
    // 40 ms) behind the frame sent before it.
    boost::system::error_code nodelay_ec;
    socket.set_option(tcp::no_delay(true), nodelay_ec);
    handler_(std::move(socket));
    accept_next();
  });
}

}  // namespace cncd::web
