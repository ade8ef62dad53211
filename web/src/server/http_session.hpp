// One HTTP connection, plain or TLS (Stream: beast::tcp_stream or beast::ssl_stream of one):
// reads each request's header within a time limit, then either reads a bounded body and
// answers (http_handlers), streams an upload into the program directory, or hands the
// connection to a WebSocket session.
#pragma once

#include <array>
#include <chrono>
#include <memory>
#include <optional>
#include <type_traits>

#include <spdlog/spdlog.h>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>

#include "http_handlers.hpp"
#include "ws_session.hpp"

namespace cncd::web {

namespace beast = boost::beast;

template <class Stream>
class HttpSession : public std::enable_shared_from_this<HttpSession<Stream>> {
  static constexpr bool kTls = !std::is_same_v<Stream, beast::tcp_stream>;

 public:
  HttpSession(App& app, Stream&& stream, Peer peer)
      : app_(app), stream_(std::move(stream)), peer_(std::move(peer)) {
    ++app_.connections;
  }
  ~HttpSession() { --app_.connections; }

  void run() {
    if constexpr (kTls) {
      beast::get_lowest_layer(stream_).expires_after(header_time());
      stream_.async_handshake(boost::asio::ssl::stream_base::server,
                              [self = this->shared_from_this()](beast::error_code ec) {
                                if (ec) return self->close();
                                self->read_header();
                              });
    } else {
      read_header();
    }
  }

 private:
  std::chrono::seconds header_time() const {
    return std::chrono::seconds(app_.limits.header_seconds);
  }
  std::chrono::seconds body_time() const {
    return std::chrono::seconds(app_.limits.body_idle_seconds);
  }

  // A read's completion handler: keeps the session alive and hands `next` the error code.
  auto then(void (HttpSession::*next)(beast::error_code)) {
    return [self = this->shared_from_this(), next](beast::error_code ec, std::size_t) {
      (*self.*next)(ec);
    };
  }

  void read_header() {
    parser_.emplace();
    parser_->header_limit(static_cast<std::uint32_t>(app_.limits.header_bytes));
    // The body's limit depends on the request (an upload's is MAX_UPLOAD_MB): set once the
    // header says which, not the parser's default 1 MiB checked against Content-Length here.
    parser_->body_limit(boost::none);
    beast::get_lowest_layer(stream_).expires_after(header_time());
    http::async_read_header(stream_, buffer_, *parser_, then(&HttpSession::on_header));
  }

  void on_header(beast::error_code ec) {
    if (ec == http::error::body_limit)
      return refuse(parser_->get(), http::status::payload_too_large, "request body too large");
    if (ec == http::error::header_limit)
      return refuse(parser_->get(), http::status::request_header_fields_too_large,
                    "request header too large");
    if (ec && ec.category() == http::make_error_code(http::error::bad_target).category() &&
        ec != http::error::end_of_stream && ec != http::error::partial_message) {
      return refuse(RequestHeader{}, http::status::bad_request,
                    "malformed request: " + ec.message());
    }
    if (ec) return close();
    auto& req = parser_->get();
    if (beast::websocket::is_upgrade(req)) return upgrade();
    if (req.method() == http::verb::put && target_path(req).starts_with("/api/programs/"))
      return start_upload();
    if (req.method() == http::verb::put)
      return refuse(req, http::status::method_not_allowed, "PUT only on programs");
    // Beast checks a body limit against Content-Length only while parsing the header, which
    // is done: a declared length is checked here, a chunked body while it is read.
    if (const auto length = parser_->content_length(); length && *length > app_.limits.body_bytes)
      return refuse(req, http::status::payload_too_large, "request body too large");
    body_parser_.emplace(std::move(*parser_));
    body_parser_->body_limit(app_.limits.body_bytes);
    beast::get_lowest_layer(stream_).expires_after(body_time());
    http::async_read(stream_, buffer_, *body_parser_, then(&HttpSession::on_body));
  }

  void on_body(beast::error_code ec) {
    if (ec == http::error::body_limit)
      return refuse(body_parser_->get(), http::status::payload_too_large, "request body too large");
    if (ec) return close();
    beast::get_lowest_layer(stream_).expires_never();
    handle_request(app_, body_parser_->release(), peer_,
                   [self = this->shared_from_this()](http::message_generator answer) {
                     self->send(std::move(answer), true);
                   });
  }

  void upgrade() {
    auto& req = parser_->get();
    if (!target_is(req, "/ws"))
      return refuse(req, http::status::not_found, "WebSocket only at /ws");
    auto check = check_upgrade(app_, req, peer_);
    if (check.refusal) return send(std::move(*check.refusal), false);
    beast::get_lowest_layer(stream_).expires_never();
    std::make_shared<WsSession<Stream>>(app_, std::move(stream_), std::move(check.identity),
                                        peer_.address)
        ->run(parser_->release());
  }

  void start_upload() {
    auto check = check_upload(app_, parser_->get(), peer_);
    if (check.refusal) return send(std::move(*check.refusal), false);
    name_ = check.name;
    user_ = check.user;
    FileStatus status;
    upload_ = app_.programs.start_upload(status);
    if (!upload_) return refuse(parser_->get(), status_of(status.error), status.message);
    upload_parser_.emplace(std::move(*parser_));
    upload_parser_->body_limit(static_cast<std::uint64_t>(app_.programs.max_upload_bytes()));
    if (beast::iequals(upload_parser_->get()[http::field::expect], "100-continue")) {
      // curl -T waits for this before it sends a large body.
      auto go_on = std::make_shared<http::response<http::empty_body>>(
          http::status::continue_, upload_parser_->get().version());
      return http::async_write(
          stream_, *go_on,
          [self = this->shared_from_this(), go_on](beast::error_code ec, std::size_t) {
            if (ec) return self->close();
            self->read_chunk();
          });
    }
    read_chunk();
  }

  void read_chunk() {
    auto& body = upload_parser_->get().body();
    body.data = chunk_.data();
    body.size = chunk_.size();
    beast::get_lowest_layer(stream_).expires_after(body_time());
    http::async_read_some(stream_, buffer_, *upload_parser_, then(&HttpSession::on_chunk));
  }

  void on_chunk(beast::error_code ec) {
    if (ec == http::error::need_buffer) ec = {};
    const auto& req = upload_parser_->get();
    if (ec == http::error::body_limit) {
      upload_.reset();  // nothing of it stays
      return refuse(req, http::status::payload_too_large,
                    "the program is over the limit of " +
                        std::to_string(app_.programs.max_upload_bytes() >> 20) +
                        " MB ([WEB] MAX_UPLOAD_MB)");
    }
    if (ec) {
      upload_.reset();
      return close();
    }
    const std::size_t got = chunk_.size() - req.body().size;
    if (got > 0) {
      const auto status = upload_->write(std::string_view(chunk_.data(), got));
      if (!status.ok()) {
        upload_.reset();
        return refuse(req, status_of(status.error), status.message);
      }
    }
    if (!upload_parser_->is_done()) return read_chunk();
    const auto size = upload_->size();
    const auto status = upload_->commit(name_, app_.running());
    upload_.reset();
    if (!status.ok())
      return send(error_response(req, status_of(status.error), status.message), true);
    spdlog::info("{} at {} uploaded program {} ({} bytes)", user_, peer_.address, name_, size);
    send(json_response(req, http::status::created, {{"name", name_}, {"size", size}}), true);
  }

  // An error answer, then the connection closes: what is left of the request is not read.
  void refuse(const RequestHeader& req, http::status status, const std::string& message) {
    send(error_response(req, status, message), false);
  }

  // Sends `answer`; reads the next request after it when both sides keep the connection.
  void send(http::message_generator answer, bool may_keep) {
    const bool keep = may_keep && answer.keep_alive();
    beast::get_lowest_layer(stream_).expires_after(body_time());
    beast::async_write(stream_, std::move(answer),
                       [self = this->shared_from_this(), keep](beast::error_code ec, std::size_t) {
                         if (ec || !keep) return self->close();
                         self->read_header();
                       });
  }

  void close() {
    if constexpr (kTls) {
      beast::get_lowest_layer(stream_).expires_after(std::chrono::seconds(2));
      stream_.async_shutdown([self = this->shared_from_this()](beast::error_code) {
        beast::error_code ignored;
        beast::get_lowest_layer(self->stream_).socket().close(ignored);
      });
    } else {
      beast::error_code ignored;
      stream_.socket().shutdown(boost::asio::ip::tcp::socket::shutdown_send, ignored);
    }
  }

  App& app_;
  Stream stream_;
  Peer peer_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::empty_body>> parser_;
  std::optional<http::request_parser<http::string_body>> body_parser_;
  std::optional<http::request_parser<http::buffer_body>> upload_parser_;
  std::unique_ptr<Upload> upload_;
  std::string name_;
  std::string user_;
  std::array<char, 64 * 1024> chunk_{};
};

}  // namespace cncd::web
