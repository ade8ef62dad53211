#include "web_client.hpp"

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <sys/time.h>
#include <chrono>

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

namespace cncd::test {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

namespace {

void set_timeout(tcp::socket& socket, int timeout_ms) {
  timeval tv{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
  setsockopt(socket.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  setsockopt(socket.native_handle(), SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
}

std::string lower(std::string text) {
  for (auto& c : text)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

}  // namespace

HttpReply http_request(int port, const std::string& method, const std::string& target,
                       const std::string& body, const Headers& headers) {
  HttpReply reply;
  asio::io_context io;
  tcp::socket socket(io);
  beast::error_code ec;
  socket.connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)), ec);
  if (ec) return reply;
  set_timeout(socket, 30000);
  http::request<http::string_body> req{http::string_to_verb(method), target, 11};
  req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
  for (const auto& [name, value] : headers)
    req.set(name, value);
  req.body() = body;
  bool chunked = false;
  for (const auto& [name, value] : headers)
    chunked |= lower(name) == "transfer-encoding";
  if (chunked) {
    req.chunked(true);
  } else if (!body.empty() || method == "PUT" || method == "POST") {
    req.prepare_payload();
  }
  http::write(socket, req, ec);
  // A server refusing a body it will not read may answer before all of it is sent.
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(256 << 20);
  http::read(socket, buffer, parser, ec);
  if (ec && !parser.is_header_done()) return reply;
  const auto& res = parser.get();
  reply.status = static_cast<int>(res.result_int());
  reply.body = res.body();
  for (const auto& field : res)
    reply.headers[lower(std::string(field.name_string()))] = std::string(field.value());
  return reply;
}

// Reads are asynchronous, run for at most the time asked: asio's blocking reads wait forever
// whatever SO_RCVTIMEO says. A read that timed out stays pending and is picked up next time.
RawReply raw_exchange(int port, const std::string& bytes, int timeout_ms) {
  RawReply reply;
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    close(fd);
    return reply;
  }
  // The server may close before taking it all (a refused request): that is an answer too.
  (void)send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  char buffer[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left)) <= 0) continue;
    const ssize_t n = recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) {
      reply.closed = true;
      break;
    }
    reply.text.append(buffer, static_cast<std::size_t>(n));
  }
  close(fd);
  return reply;
}

struct WsClient::Impl {
  asio::io_context io;
  websocket::stream<tcp::socket> ws{io};
  bool open = false;
  bool reading = false;
  bool read_done = false;
  beast::error_code read_ec;
  beast::flat_buffer buffer;
};

WsClient::WsClient() : impl_(std::make_unique<Impl>()) {}

WsClient::~WsClient() {
  if (impl_->open) drop();
}

int WsClient::open(int port, const Headers& headers) {
  beast::error_code ec;
  auto& socket = impl_->ws.next_layer();
  socket.connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)), ec);
  if (ec) return 0;
  set_timeout(socket, 30000);
  impl_->ws.set_option(websocket::stream_base::decorator([headers](websocket::request_type& req) {
    for (const auto& [name, value] : headers)
      req.set(name, value);
  }));
  impl_->ws.read_message_max(256 << 20);
  websocket::response_type res;
  impl_->ws.handshake(res, "127.0.0.1:" + std::to_string(port), "/ws", ec);
  impl_->open = !ec;
  return static_cast<int>(res.result_int());
}

void WsClient::send_text(const std::string& text) {
  if (!impl_->open) return;
  bool written = false;
  impl_->ws.text(true);
  impl_->ws.async_write(asio::buffer(text),
                        [&](beast::error_code, std::size_t) { written = true; });
  impl_->io.restart();
  while (!written && impl_->io.run_one_for(std::chrono::seconds(30)) > 0) {
  }
}

void WsClient::send(const nlohmann::json& message) {
  send_text(message.dump());
}

std::optional<nlohmann::json> WsClient::read(int timeout_ms) {
  if (!impl_->open) return std::nullopt;
  auto& impl = *impl_;
  if (!impl.reading) {
    impl.reading = true;
    impl.read_done = false;
    impl.ws.async_read(impl.buffer, [&impl](beast::error_code ec, std::size_t) {
      impl.read_done = true;
      impl.read_ec = ec;
    });
  }
  impl.io.restart();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!impl.read_done && impl.io.run_one_until(deadline) > 0) {
  }
  if (!impl.read_done) return std::nullopt;
  impl.reading = false;
  if (impl.read_ec) {
    impl.open = false;
    return std::nullopt;
  }
  auto frame = nlohmann::json::parse(beast::buffers_to_string(impl.buffer.data()), nullptr, false);
  impl.buffer.consume(impl.buffer.size());
  return frame;
}

nlohmann::json WsClient::answer_to(int id) {
  for (int i = 0; i < 100000; ++i) {
    auto frame = read();
    if (!frame) return nullptr;
    if (frame->is_object() && frame->contains("id") && (*frame)["id"] == id) return *frame;
    if (frame->is_array()) {
      for (const auto& item : *frame) {
        if (item.is_object() && item.value("id", nlohmann::json()) == id) return item;
      }
    }
    notifications_.push_back(std::move(*frame));
  }
  return nullptr;
}

nlohmann::json WsClient::call(const std::string& method, const nlohmann::json& params) {
  const int id = next_id_++;
  nlohmann::json request = {{"jsonrpc", "2.0"}, {"id", id}, {"method", method}};
  if (!params.is_null()) request["params"] = params;
  send(request);
  return answer_to(id);
}

void WsClient::drop() {
  beast::error_code ec;
  impl_->open = false;
  impl_->ws.next_layer().shutdown(tcp::socket::shutdown_both, ec);
  impl_->ws.next_layer().close(ec);
  impl_->open = false;
}

void WsClient::close() {
  if (!impl_->open) return;
  bool closed = false;
  impl_->ws.async_close(websocket::close_code::normal, [&](beast::error_code) { closed = true; });
  impl_->io.restart();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (!closed && impl_->io.run_one_until(deadline) > 0) {
  }
  drop();
}

bool WsClient::is_open() const {
  return impl_->open;
}

}  // namespace cncd::test
