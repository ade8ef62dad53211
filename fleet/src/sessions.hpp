// cncd-fleet's connections: HTTP requests (the page's files, GET /api/machines) read with a
// time and size limit, and the browsers' WebSockets on /ws, which only receive: the table's
// snapshot, then its changes. A browser that does not read is closed once 16 MiB wait for it.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include <spdlog/spdlog.h>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "fleet_app.hpp"
#include "http_common.hpp"
#include "ws_outbox.hpp"

namespace cncd::fleet {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

inline constexpr std::size_t kWsQueueBytes = 16 << 20;
inline constexpr std::size_t kMaxConnections = 1024;

class WsViewer : public Viewer, public std::enable_shared_from_this<WsViewer> {
 public:
  WsViewer(FleetApp& app, beast::tcp_stream&& stream, std::string address)
      : app_(app),
        ws_(std::move(stream)),
        address_(std::move(address)),
        out_(kWsQueueBytes),
        kill_timer_(app.io) {
    ++app_.connections;
  }
  ~WsViewer() override {
    cleanup();
    --app_.connections;
  }

  void run(http::request<http::string_body> req) {
    req_ = std::move(req);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, "cncd-fleet"); }));
    ws_.read_message_max(4096);
    ws_.async_accept(req_, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      self->accepted_ = true;
      spdlog::info("a browser at {} watches", self->address_);
      self->app_.add(self.get());
      self->read_next();
    });
  }

  void send(std::string frame) override {
    if (closing_) return;
    const std::size_t size = frame.size();
    if (!out_.push(std::move(frame))) {
      spdlog::warn("the browser at {}: WebSocket closed, {} bytes unread", address_,
                   out_.bytes() + size);
      return close_with("the browser does not read what it is sent");
    }
    out_.pump(ws_, shared_from_this(), [self = shared_from_this()](auto) { self->cleanup(); });
  }

  void close_with(const std::string& reason) override {
    boost::asio::post(app_.io, [self = shared_from_this(), reason] { self->shut(reason); });
  }

 private:
  // The page sends nothing that matters; reading keeps pings and the close handshake going.
  void read_next() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->cleanup();
      self->in_.consume(self->in_.size());
      self->read_next();
    });
  }

  void shut(const std::string& reason) {
    if (closing_) return;
    cleanup();
    websocket::close_reason why(websocket::close_code::going_away);
    why.reason = reason.substr(0, 120);
    ws_.async_close(why,
                    [self = shared_from_this()](beast::error_code) { self->kill_timer_.cancel(); });
    kill_timer_.expires_after(std::chrono::seconds(2));
    kill_timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec) return;
      beast::error_code ignored;
      beast::get_lowest_layer(self->ws_).socket().close(ignored);
    });
  }

  void cleanup() {
    if (closing_) return;
    closing_ = true;
    out_.stop();
    if (accepted_) {
      app_.remove(this);
      spdlog::info("the browser at {} left", address_);
    }
  }

  FleetApp& app_;
  websocket::stream<beast::tcp_stream> ws_;
  std::string address_;
  http::request<http::string_body> req_;
  beast::flat_buffer in_;
  web::WsOutbox out_;
  boost::asio::steady_timer kill_timer_;
  bool accepted_ = false;
  bool closing_ = false;
};

class HttpConnection : public std::enable_shared_from_this<HttpConnection> {
 public:
  HttpConnection(FleetApp& app, boost::asio::ip::tcp::socket&& socket, std::string address)
      : app_(app), stream_(std::move(socket)), address_(std::move(address)) {
    ++app_.connections;
  }
  ~HttpConnection() { --app_.connections; }

  void read_next() {
    parser_.emplace();
    parser_->header_limit(8 * 1024);
    parser_->body_limit(8 * 1024);
    stream_.expires_after(std::chrono::seconds(10));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                       if (ec) return self->close();
                       self->on_request(self->parser_->release());
                     });
  }

 private:
  void on_request(http::request<http::string_body> req) {
    using web::error_response;
    const auto path = web::target_path(req);
    if (websocket::is_upgrade(req)) {
      if (path != "/ws")
        return send(error_response(req, http::status::not_found, "WebSocket only at /ws"));
      if (!app_.origin_allowed(req[http::field::origin], req[http::field::host]))
        return send(error_response(req, http::status::forbidden,
                                   "origin " + std::string(req[http::field::origin]) +
                                       " may not open a WebSocket here (--allowed-origin)"));
      if (app_.viewers() >= app_.options.max_clients)
        return send(error_response(req, http::status::service_unavailable,
                                   "too many browsers (--max-clients)"));
      stream_.expires_never();
      return std::make_shared<WsViewer>(app_, std::move(stream_), address_)->run(std::move(req));
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return send(error_response(req, http::status::method_not_allowed, "GET only"));
    if (path == "/api/machines")
      return send(web::json_response(req, http::status::ok, app_.snapshot()));
    if (path == "/" || path == "/index.html")
      return send(web::serve_file(app_.options.www, req, "index.html"));
    const auto relative = web::static_path(path);
    if (!relative) return send(error_response(req, http::status::not_found, "no such file"));
    send(web::serve_file(app_.options.www, req, *relative));
  }

  void send(http::message_generator answer) {
    const bool keep = answer.keep_alive();
    stream_.expires_after(std::chrono::seconds(30));
    beast::async_write(stream_, std::move(answer),
                       [self = shared_from_this(), keep](beast::error_code ec, std::size_t) {
                         if (ec || !keep) return self->close();
                         self->read_next();
                       });
  }

  void close() {
    beast::error_code ignored;
    stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ignored);
  }

  FleetApp& app_;
  beast::tcp_stream stream_;
  std::string address_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace cncd::fleet
