#include "shdr.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <deque>

#include <boost/asio/ip/address.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/streambuf.hpp>
#include <boost/asio/write.hpp>

#include "json_read.hpp"
#include "tcp_listen.hpp"

namespace cncd::telemetry {

using boost::asio::ip::tcp;
using nlohmann::json;

namespace {

constexpr const char* kUnavailable = "UNAVAILABLE";

// Four decimals at the most, no trailing zeros: a position, a speed.
std::string decimal(double value) {
  char text[48];
  std::snprintf(text, sizeof text, "%.4f", value);
  std::string out = text;
  while (out.back() == '0')
    out.pop_back();
  if (out.back() == '.') out.pop_back();
  return out == "-0" ? "0" : out;
}

// SHDR separates fields with '|' and items with lines: neither may appear in a value.
std::string clean(const std::string& text) {
  std::string out = text;
  for (char& c : out) {
    if (c == '|' || c == '\n' || c == '\r') c = ' ';
  }
  return out;
}

std::string execution(const json& s) {
  const std::string exec = text_at(s, "exec");
  if (exec == "running") return "ACTIVE";
  if (exec == "paused") return "FEED_HOLD";
  return text_at(s, "state") == "on" ? "READY" : "STOPPED";
}

std::string mode(const json& s) {
  const std::string m = text_at(s, "mode");
  if (m == "auto") return "AUTOMATIC";
  if (m == "mdi") return "MANUAL_DATA_INPUT";
  return "MANUAL";
}

}  // namespace

ShdrItems shdr_items(const MachineFeed& feed, const std::vector<char>& axes) {
  ShdrItems items;
  auto& v = items.samples;
  const json& s = feed.status();
  const bool known = feed.connected() && s.contains("state");
  v["avail"] = feed.connected() ? "AVAILABLE" : kUnavailable;
  const char* keys[] = {
      "estop",  "execution", "mode", "program", "line", "path_feedrate", "path_feedrate_override",
      "Sspeed", "Sovr",      "tool"};
  for (const char* key : keys)
    v[key] = kUnavailable;
  for (const char axis : axes)
    v[std::string(1, axis) + "pos"] = kUnavailable;
  const json& jobs = feed.jobs();
  v["partcount"] = jobs.contains("parts") ? std::to_string(count_at(jobs, "parts")) : kUnavailable;
  items.conditions["system"] = known ? "NORMAL||||" : std::string(kUnavailable) + "||||";
  if (!known) return items;
  const json& program = object_at(s, "program");
  const json& spindle = object_at(s, "spindle");
  const json& overrides = object_at(s, "overrides");
  v["estop"] = text_at(s, "state") == "estop" ? "TRIGGERED" : "ARMED";
  v["execution"] = execution(s);
  v["mode"] = mode(s);
  const std::string path = text_at(program, "path");
  v["program"] = path.empty() ? kUnavailable : clean(path);
  v["line"] = std::to_string(static_cast<long long>(number_at(program, "line")));
  v["path_feedrate"] = decimal(number_at(s, "velocity"));
  v["path_feedrate_override"] = decimal(number_at(overrides, "feed") * 100);
  v["Sspeed"] = decimal(number_at(spindle, "actual_rpm"));
  v["Sovr"] = decimal(number_at(spindle, "override", 1) * 100);
  v["tool"] = std::to_string(static_cast<long long>(number_at(object_at(s, "tool"), "number")));
  const json& actual = object_at(object_at(s, "position"), "actual");
  for (const char axis : axes) {
    const std::string key(1, static_cast<char>(axis - 'A' + 'a'));
    if (actual.contains(key))
      v[std::string(1, axis) + "pos"] = decimal(number_at(actual, key.c_str()));
  }
  if (const std::string fault = text_at(s, "fault"); !fault.empty()) {
    items.conditions["system"] = "FAULT||||" + clean(fault);
  }
  return items;
}

std::string shdr_time() {
  const auto now = std::chrono::system_clock::now();
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch());
  const std::time_t seconds = static_cast<std::time_t>(ms.count() / 1000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[96];
  std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900,
                utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec,
                static_cast<int>(ms.count() % 1000));
  return text;
}

std::string shdr_lines(const ShdrItems& before, const ShdrItems& now, const std::string& time) {
  std::string samples;
  for (const auto& [key, value] : now.samples) {
    const auto it = before.samples.find(key);
    if (it == before.samples.end() || it->second != value) samples += "|" + key + "|" + value;
  }
  std::string out = samples.empty() ? "" : time + samples + "\n";
  for (const auto& [key, value] : now.conditions) {
    const auto it = before.conditions.find(key);
    if (it == before.conditions.end() || it->second != value)
      out += time + "|" + key + "|" + value + "\n";
  }
  return out;
}

std::string devices_xml(const std::string& machine_id, const std::string& machine_name,
                        const std::vector<char>& axes) {
  auto item = [](const std::string& id, const char* category, const char* type,
                 const std::string& extra = "") {
    return "          <DataItem category=\"" + std::string(category) + "\" id=\"" + id +
           "\" name=\"" + id + "\" type=\"" + type + "\"" + extra + "/>\n";
  };
  std::string axes_xml;
  for (const char axis : axes) {
    const std::string name(1, axis);
    axes_xml += "        <Linear id=\"" + name + "\" name=\"" + name +
                "\">\n          <DataItems>\n" +
                item(name + "pos", "SAMPLE", "POSITION",
                     " subType=\"ACTUAL\" units=\"MILLIMETER\" coordinateSystem=\"MACHINE\"") +
                "          </DataItems>\n        </Linear>\n";
  }
  // Names and ids are the machine id, which [TELEMETRY] keeps to XML-safe characters.
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<MTConnectDevices xmlns=\"urn:mtconnect.org:MTConnectDevices:1.3\">\n"
         "  <Header creationTime=\"" +
         shdr_time() +
         "\" sender=\"cncd-telemetry\" "
         "instanceId=\"1\" version=\"1.3\" bufferSize=\"131072\"/>\n"
         "  <Devices>\n"
         "    <Device id=\"" +
         machine_id + "\" name=\"" + machine_id + "\" uuid=\"" + machine_id +
         "\">\n"
         "      <Description manufacturer=\"cncd\">" +
         clean(machine_name) +
         "</Description>\n"
         "      <DataItems>\n" +
         item("avail", "EVENT", "AVAILABILITY") + item("estop", "EVENT", "EMERGENCY_STOP") +
         "      </DataItems>\n      <Components>\n"
         "        <Controller id=\"controller\" name=\"controller\">\n          <DataItems>\n" +
         item("system", "CONDITION", "SYSTEM") +
         "          </DataItems>\n          <Components>\n"
         "            <Path id=\"path\" name=\"path\">\n              <DataItems>\n" +
         item("execution", "EVENT", "EXECUTION") + item("mode", "EVENT", "CONTROLLER_MODE") +
         item("program", "EVENT", "PROGRAM") + item("line", "EVENT", "LINE") +
         item("partcount", "EVENT", "PART_COUNT") + item("tool", "EVENT", "TOOL_NUMBER") +
         item("path_feedrate", "SAMPLE", "PATH_FEEDRATE",
              " subType=\"ACTUAL\" units=\"MILLIMETER/SECOND\"") +
         item("path_feedrate_override", "EVENT", "PATH_FEEDRATE_OVERRIDE",
              " subType=\"PROGRAMMED\"") +
         "              </DataItems>\n            </Path>\n          </Components>\n"
         "        </Controller>\n        <Axes id=\"axes\" name=\"axes\">\n"
         "          <Components>\n" +
         axes_xml + "        <Rotary id=\"C\" name=\"C\">\n          <DataItems>\n" +
         item("Sspeed", "SAMPLE", "ROTARY_VELOCITY",
              " subType=\"ACTUAL\" units=\"REVOLUTION/MINUTE\"") +
         item("Sovr", "EVENT", "ROTARY_VELOCITY_OVERRIDE") +
         "          </DataItems>\n        </Rotary>\n          </Components>\n"
         "        </Axes>\n      </Components>\n    </Device>\n  </Devices>\n"
         "</MTConnectDevices>\n";
}

class ShdrServer::Agent : public std::enable_shared_from_this<Agent> {
 public:
  static constexpr std::size_t kMaxQueued = 1 << 20;

  Agent(tcp::socket socket, ShdrServer& server)
      : socket_(std::move(socket)), server_(server), in_(1024) {}
  void start(std::string first) {
    send(std::move(first));
    read();
  }
  // An agent that does not read is dropped before its queue grows past 1 MiB.
  void send(std::string text) {
    if (closed_ || text.empty()) return;
    queued_ += text.size();
    if (queued_ > kMaxQueued) {
      close();
      return;
    }
    out_.push_back(std::move(text));
    if (!writing_) write_next();
  }
  void close() {
    if (closed_) return;
    closed_ = true;
    boost::system::error_code ignored;
    socket_.close(ignored);
    server_.agents_.erase(shared_from_this());
  }

 private:
  void read() {
    boost::asio::async_read_until(
        socket_, in_, '\n',
        [self = shared_from_this()](boost::system::error_code ec, std::size_t n) {
          if (ec) {
            self->close();  // gone, or a line over 1 KiB
            return;
          }
          std::string line(boost::asio::buffers_begin(self->in_.data()),
                           boost::asio::buffers_begin(self->in_.data()) + static_cast<long>(n));
          self->in_.consume(n);
          if (line.rfind("* PING", 0) == 0) self->send("* PONG 10000\n");
          self->read();
        });
  }
  void write_next() {
    writing_ = true;
    boost::asio::async_write(
        socket_, boost::asio::buffer(out_.front()),
        [self = shared_from_this()](boost::system::error_code ec, std::size_t) {
          if (ec) {
            self->close();
            return;
          }
          self->queued_ -= self->out_.front().size();
          self->out_.pop_front();
          self->writing_ = false;
          if (!self->out_.empty()) self->write_next();
        });
  }

  tcp::socket socket_;
  ShdrServer& server_;
  boost::asio::streambuf in_;
  std::deque<std::string> out_;
  std::size_t queued_ = 0;
  bool writing_ = false;
  bool closed_ = false;
};

ShdrServer::ShdrServer(boost::asio::io_context& io, const MachineFeed& feed, std::vector<char> axes)
    : io_(io), feed_(feed), axes_(std::move(axes)), acceptor_(io), throttle_(io) {}

std::string ShdrServer::listen(const std::string& address, int port) {
  if (auto error = listen_on(acceptor_, address, port); !error.empty()) return error;
  sent_ = shdr_items(feed_, axes_);
  accept();
  return "";
}

int ShdrServer::port() const {
  boost::system::error_code ec;
  return acceptor_.local_endpoint(ec).port();
}

void ShdrServer::stop() {
  boost::system::error_code ignored;
  acceptor_.close(ignored);
  throttle_.cancel();
  for (const auto& agent : std::set(agents_))
    agent->close();
}

void ShdrServer::accept() {
  acceptor_.async_accept(io_, [this](boost::system::error_code ec, tcp::socket socket) {
    if (ec == boost::asio::error::operation_aborted) return;
    if (!ec) {
      if (agents_.size() >= kMaxAgents) {
        boost::system::error_code ignored;
        socket.close(ignored);
      } else {
        flush();  // the others are told what changed first: all then start from the same
        auto agent = std::make_shared<Agent>(std::move(socket), *this);
        agents_.insert(agent);
        agent->start(shdr_lines({}, sent_, shdr_time()));
      }
    }
    accept();
  });
}

void ShdrServer::changed() {
  pending_ = true;
  if (waiting_) return;
  flush();
  waiting_ = true;
  throttle_.expires_after(std::chrono::milliseconds(100));
  throttle_.async_wait([this](boost::system::error_code ec) {
    waiting_ = false;
    if (!ec && pending_) changed();
  });
}

void ShdrServer::flush() {
  pending_ = false;
  const ShdrItems now = shdr_items(feed_, axes_);
  const std::string lines = shdr_lines(sent_, now, shdr_time());
  sent_ = now;
  if (lines.empty()) return;
  for (const auto& agent : std::set(agents_))
    agent->send(lines);
}

}  // namespace cncd::telemetry
