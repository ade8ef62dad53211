// A real mosquitto broker on a loopback port of its own, and a real MQTT subscriber
// (libmosquitto) that keeps every message it gets.
#pragma once

#include <mosquitto.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "telemetry_fixture.hpp"

namespace cncd::test {

// A port no one listened on a moment ago.
inline int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t size = sizeof addr;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &size);
  ::close(fd);
  return ntohs(addr.sin_port);
}

class Broker {
 public:
  explicit Broker(const std::filesystem::path& dir) : dir_(dir) {}
  ~Broker() { stop(); }
  // mosquitto.conf lines for its listener, in place of "allow_anonymous true" (a password
  // file, TLS certificates), before the next start().
  void settings(std::string lines) { settings_ = std::move(lines); }
  // Starts mosquitto on `port` (a free one when 0); "" or why not.
  std::string start(int port = 0) {
    for (int attempt = 0; attempt < 5; ++attempt) {
      port_ = port != 0 ? port : free_port();
      const auto conf = dir_ / "mosquitto.conf";
      std::ofstream(conf) << "listener " << port_ << " 127.0.0.1\n"
                          << settings_ << "persistence false\n";
      process_ = std::make_unique<BackgroundCommand>(
          std::vector<std::string>{"/usr/sbin/mosquitto", "-c", conf.string()});
      for (int i = 0; i < 500; ++i) {
        const int fd = connect_loopback(port_, 1);
        if (fd >= 0) {
          ::close(fd);
          return "";
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      stop();
      if (port != 0) break;
    }
    return "mosquitto did not start";
  }
  void stop() {
    if (!process_) return;
    ::kill(process_->pid(), SIGTERM);
    process_->wait();
    process_.reset();
  }
  int port() const { return port_; }

 private:
  std::filesystem::path dir_;
  std::unique_ptr<BackgroundCommand> process_;
  int port_ = 0;
  std::string settings_ = "allow_anonymous true\n";
};

// How a Subscriber logs in: a user name and password, and a CA file for TLS.
struct SubscriberLogin {
  std::string username;
  std::string password;
  std::string tls_ca;
};

struct Message {
  std::string topic;
  std::string payload;
  bool retained = false;
};

class Subscriber {
 public:
  Subscriber(int port, std::string filter, const SubscriberLogin& login = {})
      : filter_(std::move(filter)) {
    mosquitto_lib_init();
    mosq_ = mosquitto_new(nullptr, true, this);
    if (!login.username.empty())
      mosquitto_username_pw_set(mosq_, login.username.c_str(), login.password.c_str());
    if (!login.tls_ca.empty())
      mosquitto_tls_set(mosq_, login.tls_ca.c_str(), nullptr, nullptr, nullptr, nullptr);
    mosquitto_reconnect_delay_set(mosq_, 1, 1, false);
    mosquitto_connect_callback_set(mosq_, [](mosquitto* m, void* self, int rc) {
      if (rc == 0)
        mosquitto_subscribe(m, nullptr, static_cast<Subscriber*>(self)->filter_.c_str(), 1);
    });
    mosquitto_subscribe_callback_set(mosq_, [](mosquitto*, void* self, int, int, const int*) {
      auto* me = static_cast<Subscriber*>(self);
      std::lock_guard lock(me->mutex_);
      ++me->subscribed_;
    });
    mosquitto_message_callback_set(mosq_, [](mosquitto*, void* self, const mosquitto_message* m) {
      auto* me = static_cast<Subscriber*>(self);
      std::lock_guard lock(me->mutex_);
      me->messages_.push_back({m->topic,
                               std::string(static_cast<const char*>(m->payload),
                                           static_cast<std::size_t>(m->payloadlen)),
                               m->retain});
    });
    mosquitto_connect_async(mosq_, "127.0.0.1", port, 5);
    mosquitto_loop_start(mosq_);
  }
  ~Subscriber() {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, true);
    mosquitto_destroy(mosq_);
  }
  // Waits until the subscription has been granted `times` times in all (once a connection).
  bool subscribed(int times = 1) {
    return wait([&] { return subscribed_ >= times; });
  }
  std::vector<Message> messages() {
    std::lock_guard lock(mutex_);
    return messages_;
  }
  // Waits until a message on a topic ending in `suffix` whose payload holds `text` came.
  bool got(const std::string& suffix, const std::string& text, int seconds = 60) {
    return wait(
        [&] {
          for (const auto& m : messages_) {
            if (m.topic.ends_with(suffix) && m.payload.find(text) != std::string::npos) return true;
          }
          return false;
        },
        seconds);
  }

 private:
  template <typename Done>
  bool wait(Done done, int seconds = 60) {
    for (int i = 0; i < seconds * 100; ++i) {
      {
        std::lock_guard lock(mutex_);
        if (done()) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  std::string filter_;
  mosquitto* mosq_ = nullptr;
  std::mutex mutex_;
  std::vector<Message> messages_;
  int subscribed_ = 0;
};

}  // namespace cncd::test
