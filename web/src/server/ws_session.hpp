// One WebSocket on /ws, plain or TLS: frames from the client go through WsRpc to its own
// connection to cncd; cncd's lines come back one per frame. A client that does not read gets
// at most ServerLimits::ws_queue_bytes queued, then it is closed: it cannot make cncd-web
// buffer without bound, nor hold up the others (each has its own queue).
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include <spdlog/spdlog.h>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>

#include "app.hpp"
#include "upstream.hpp"
#include "ws_outbox.hpp"
#include "ws_rpc.hpp"

namespace cncd::web {

template <class Stream>
class WsSession : public WsPeer, public std::enable_shared_from_this<WsSession<Stream>> {
 public:
  WsSession(App& app, Stream&& stream, Identity who, std::string address)
      : app_(app),
        ws_(std::move(stream)),
        rpc_(app, std::move(who), address),
        address_(std::move(address)),
        session_id_(rpc_.identity().session.id),
        out_(app.limits.ws_queue_bytes),
        kill_timer_(app.io) {
    ++app_.connections;
  }
  ~WsSession() override {
    cleanup();
    --app_.connections;
  }

  void run(boost::beast::http::request<boost::beast::http::empty_body> req) {
    namespace websocket = boost::beast::websocket;
    req_ = std::move(req);
    ws_.set_option(websocket::stream_base::timeout::suggested(boost::beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
      res.set(boost::beast::http::field::server, "cncd-web");
    }));
    ws_.read_message_max(app_.limits.ws_message_bytes);
    ws_.async_accept(req_, [self = this->shared_from_this()](boost::beast::error_code ec) {
      if (ec) return;
      self->on_accept();
    });
  }

  void notify(const std::string& text) override { queue(text); }
  void close_with(const std::string& reason) override {
    // Maybe called from within this session's own handler: later, on a clean stack.
    boost::asio::post(app_.io, [self = this->shared_from_this(), reason] { self->shut(reason); });
  }
  const std::string& session_id() const override { return session_id_; }

 private:
  void on_accept() {
    app_.peers.insert(this);
    spdlog::info("{} ({}) connected from {}", rpc_.identity().user, role_name(rpc_.identity().role),
                 address_);
    upstream_ = std::make_shared<client::Upstream>(app_.io, app_.socket_path,
                                                   app_.limits.upstream_line_bytes);
    std::weak_ptr<WsSession> weak = this->shared_from_this();
    upstream_->start(
        [weak](std::string line) {
          if (auto self = weak.lock()) self->queue(line);
        },
        [weak](const std::string& why) {
          if (auto self = weak.lock()) self->shut(why);
        });
    read_next();
  }

  void read_next() {
    ws_.async_read(in_,
                   [self = this->shared_from_this()](boost::beast::error_code ec, std::size_t) {
                     if (ec) return self->cleanup();
                     const std::string text = boost::beast::buffers_to_string(self->in_.data());
                     self->in_.consume(self->in_.size());
                     auto out = self->rpc_.on_client(text);
                     for (auto& line : out.to_daemon)
                       self->upstream_->send(std::move(line));
                     for (auto& frame : out.to_client)
                       self->queue(frame);
                     if (out.later) self->run_later(std::move(*out.later));
                     if (!self->closing_) self->read_next();
                   });
  }

  // The slow part on a worker; the answer back on the I/O thread, to this socket while open
  // (the change itself is made either way).
  void run_later(WsRpc::Later later) {
    boost::asio::post(app_.workers, [&app = app_, later = std::move(later),
                                     weak = this->weak_from_this()]() mutable {
      std::string done = later.work();
      boost::asio::post(app.io, [later = std::move(later), done = std::move(done),
                                 weak = std::move(weak)]() mutable {
        const std::string frame = later.finish(std::move(done));
        if (auto self = weak.lock(); self && !frame.empty()) self->queue(frame);
      });
    });
  }

  void queue(const std::string& text) {
    if (closing_) return;
    if (!out_.push(text)) {
      spdlog::warn("{} at {}: WebSocket closed, {} bytes unread", rpc_.identity().user, address_,
                   out_.bytes() + text.size());
      return shut("the client does not read what it is sent");
    }
    out_.pump(ws_, this->shared_from_this(),
              [self = this->shared_from_this()](auto) { self->cleanup(); });
  }

  // Closes with `reason`; a client that does not take the close frame is cut off.
  void shut(const std::string& reason) {
    if (closing_) return;
    cleanup();
    namespace websocket = boost::beast::websocket;
    websocket::close_reason why(websocket::close_code::policy_error);
    why.reason = reason.substr(0, 120);  // a close frame's reason has at most 123 bytes
    ws_.async_close(why, [self = this->shared_from_this()](boost::beast::error_code) {
      self->kill_timer_.cancel();
    });
    kill_timer_.expires_after(std::chrono::seconds(2));
    kill_timer_.async_wait([self = this->shared_from_this()](boost::beast::error_code ec) {
      if (ec) return;
      boost::beast::error_code ignored;
      boost::beast::get_lowest_layer(self->ws_).socket().close(ignored);
    });
  }

  // The WebSocket is over: its jogs stopped, its upstream closed, the lease released when it
  // was its session's last.
  void cleanup() {
    if (closing_) return;
    closing_ = true;
    out_.stop();
    if (!app_.peers.erase(this)) return;  // never accepted
    if (upstream_) {
      for (auto& line : rpc_.on_close())
        upstream_->send(std::move(line));
      upstream_->close_after_sending();
    }
    bool last = true;
    for (auto* peer : app_.peers) {
      if (peer->session_id() == session_id_) last = false;
    }
    if (last) app_.lease.session_closed(session_id_);
    spdlog::info("{} at {} disconnected", rpc_.identity().user, address_);
  }

  App& app_;
  boost::beast::websocket::stream<Stream> ws_;
  WsRpc rpc_;
  std::string address_;
  std::string session_id_;
  boost::beast::http::request<boost::beast::http::empty_body> req_;
  boost::beast::flat_buffer in_;
  WsOutbox out_;
  bool closing_ = false;
  std::shared_ptr<client::Upstream> upstream_;
  boost::asio::steady_timer kill_timer_;
};

}  // namespace cncd::web
