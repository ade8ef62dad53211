// The end of a server's main: runs the io_context until SIGTERM or SIGINT, then `shut` (stop
// listening, close the WebSockets) and 300 ms for the close frames to go out.
#pragma once

#include <functional>

#include <boost/asio/io_context.hpp>

namespace cncd::web {

void run_until_signal(boost::asio::io_context& io, std::function<void()> shut);

}  // namespace cncd::web
