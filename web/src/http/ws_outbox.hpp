// The frames queued to one WebSocket, written in order one at a time. A client that does not
// read gets at most `limit` bytes queued: push() then refuses and its owner closes the
// WebSocket, so a slow browser can neither make the server buffer without bound nor hold up
// the others (each has its own outbox).
#pragma once

#include <cstddef>
#include <deque>
#include <string>

#include <boost/asio/buffer.hpp>
#include <boost/beast/core/error.hpp>

namespace cncd::web {

class WsOutbox {
 public:
  explicit WsOutbox(std::size_t limit) : limit_(limit) {}

  // Queues `text`; false (nothing queued) when the bytes unwritten would pass the limit.
  bool push(std::string text) {
    if (bytes_ + text.size() > limit_) return false;
    bytes_ += text.size();
    out_.push_back(std::move(text));
    return true;
  }
  std::size_t bytes() const { return bytes_; }
  // Nothing more is written (a write under way finishes: out_ keeps its front).
  void stop() { stopped_ = true; }

  // Writes what is queued on `ws` unless a write is under way. `keep` (the session's
  // shared_ptr) keeps this outbox alive until the write ends; `fail(ec)` when one fails.
  template <class Ws, class Keep, class Fail>
  void pump(Ws& ws, Keep keep, Fail fail) {
    if (out_.empty() || writing_ || stopped_) return;
    writing_ = true;
    ws.text(true);
    ws.async_write(boost::asio::buffer(out_.front()),
                   [this, &ws, keep, fail](boost::beast::error_code ec, std::size_t) {
                     writing_ = false;
                     if (ec) return fail(ec);
                     bytes_ -= out_.front().size();
                     out_.pop_front();
                     pump(ws, keep, fail);
                   });
  }

 private:
  std::size_t limit_;
  std::deque<std::string> out_;
  std::size_t bytes_ = 0;
  bool writing_ = false;
  bool stopped_ = false;
};

}  // namespace cncd::web
