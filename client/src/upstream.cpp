#include "upstream.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/write.hpp>

namespace cncd::client {

namespace asio = boost::asio;
using Protocol = asio::local::stream_protocol;

Upstream::Upstream(asio::io_context& io, std::string socket_path, std::size_t max_line)
    : socket_(io), path_(std::move(socket_path)), in_(max_line) {}

void Upstream::start(LineHandler on_line, CloseHandler on_close) {
  on_line_ = std::move(on_line);
  on_close_ = std::move(on_close);
  socket_.async_connect(
      Protocol::endpoint(path_), [self = shared_from_this()](const boost::system::error_code& ec) {
        if (self->closed_) return;
        if (ec) return self->fail("cannot connect to cncd at " + self->path_ + ": " + ec.message());
        self->connected_ = true;
        self->write_next();
        self->read_next();
      });
}

void Upstream::send(std::string line) {
  if (closed_ || closing_) return;
  line += '\n';
  queued_bytes_ += line.size();
  out_.push_back(std::move(line));
  write_next();
}

void Upstream::write_next() {
  if (!connected_ || writing_ || closed_) return;
  if (out_.empty()) {
    if (closing_) close();
    return;
  }
  writing_ = true;
  asio::async_write(socket_, asio::buffer(out_.front()),
                    [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                      self->writing_ = false;
                      if (self->closed_) return;
                      if (ec) return self->fail("writing to cncd: " + ec.message());
                      self->queued_bytes_ -= self->out_.front().size();
                      self->out_.pop_front();
                      self->write_next();
                    });
}

void Upstream::read_next() {
  asio::async_read_until(
      socket_, in_, '\n',
      [self = shared_from_this()](const boost::system::error_code& ec, std::size_t n) {
        if (self->closed_) return;
        if (ec == asio::error::not_found) return self->fail("cncd sent a line over the limit");
        if (ec == asio::error::eof) return self->fail("cncd closed the connection");
        if (ec) return self->fail("reading from cncd: " + ec.message());
        std::string line(
            asio::buffers_begin(self->in_.data()),
            asio::buffers_begin(self->in_.data()) + static_cast<std::ptrdiff_t>(n - 1));
        self->in_.consume(n);
        self->on_line_(std::move(line));
        if (!self->closed_) self->read_next();
      });
}

void Upstream::close_after_sending() {
  closing_ = true;
  on_close_ = nullptr;  // the WebSocket is gone: nobody to tell
  if (!writing_ && out_.empty()) close();
}

void Upstream::close() {
  if (closed_) return;
  closed_ = true;
  boost::system::error_code ignored;
  socket_.shutdown(Protocol::socket::shutdown_both, ignored);
  socket_.close(ignored);
  out_.clear();
  queued_bytes_ = 0;
}

void Upstream::fail(const std::string& why) {
  if (closed_) return;
  close();
  if (on_close_) on_close_(why);
}

}  // namespace cncd::client
