#include "run_until_signal.hpp"

#include <csignal>
#include <memory>

#include <spdlog/spdlog.h>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

namespace cncd::web {

void run_until_signal(boost::asio::io_context& io, std::function<void()> shut) {
  boost::asio::signal_set signals(io, SIGTERM, SIGINT);
  signals.async_wait([&io, shut = std::move(shut)](const boost::system::error_code& ec,
                                                   int signal) {
    if (ec) return;
    spdlog::info("signal {}: shutting down", signal);
    shut();
    auto timer = std::make_shared<boost::asio::steady_timer>(io, std::chrono::milliseconds(300));
    timer->async_wait([&io, timer](const boost::system::error_code&) { io.stop(); });
  });
  io.run();
}

}  // namespace cncd::web
