// Opens a TCP acceptor on address:port for cncd-telemetry's servers (/metrics, SHDR).
#pragma once

#include <string>

#include <boost/asio/ip/address.hpp>
#include <boost/asio/ip/tcp.hpp>

namespace cncd::telemetry {

// "" or what went wrong ("cannot listen on 127.0.0.1:7878: Address already in use").
inline std::string listen_on(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address,
                             int port) {
  using boost::asio::ip::tcp;
  boost::system::error_code ec;
  const auto ip = boost::asio::ip::make_address(address, ec);
  if (ec) return "'" + address + "' is not an IP address";
  const tcp::endpoint endpoint(ip, static_cast<unsigned short>(port));
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(boost::asio::socket_base::max_listen_connections, ec);
  if (ec) return "cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message();
  return "";
}

}  // namespace cncd::telemetry
