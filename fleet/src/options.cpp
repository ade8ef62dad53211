#include "options.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include <boost/asio/ip/address.hpp>

#include "cncd/config/machine_config.hpp"

namespace cncd::fleet {
namespace {

bool whole_number(const std::string& text, long long low, long long high, long long& out) {
  const auto* end = text.data() + text.size();
  const auto [at, ec] = std::from_chars(text.data(), end, out);
  return ec == std::errc() && at == end && out >= low && out <= high;
}

// ADDRESS:PORT with an IP address ("[::1]:8090" for IPv6).
bool address_port(const std::string& text, std::string& address, int& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) return false;
  std::string host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  boost::system::error_code ec;
  boost::asio::ip::make_address(host, ec);
  long long number = 0;
  if (ec || !whole_number(text.substr(colon + 1), 0, 65535, number)) return false;
  address = host;
  port = static_cast<int>(number);
  return true;
}

}  // namespace

std::string usage() {
  return "usage: cncd-fleet [options]\n\n"
         "  --listen ADDRESS:PORT     the page's address (default 127.0.0.1:8090)\n"
         "  --www DIR                 the page's files (default <bin>/../share/cncd/fleet-www)\n"
         "  --ini MACHINE.ini         take the broker and credentials from its [TELEMETRY]\n"
         "  --broker HOST[:PORT]      the MQTT broker (default 127.0.0.1:1883)\n"
         "  --username NAME           the broker's user name\n"
         "  --password-file FILE      the broker's password, the file's first line (default\n"
         "                            $CREDENTIALS_DIRECTORY/mqtt-password when it exists)\n"
         "  --tls-ca FILE             a CA certificate: the broker is reached over TLS\n"
         "  --protocol 5|3.1.1        the MQTT version (default 5)\n"
         "  --topics PATTERN          machines' topic prefixes, '+' a level (default cncd/+)\n"
         "  --max-machines N          machines in the table at most (default 2000)\n"
         "  --max-payload BYTES       a larger message is ignored (default 65536)\n"
         "  --max-clients N           browsers at once (default 64)\n"
         "  --push-ms N               changes go to the browsers at most this often (default 50)\n"
         "  --allowed-origin ORIGIN   another origin the page's WebSocket may come from\n"
         "  --log-level L             trace|debug|info|warn|error|critical|off (default info)\n";
}

Parsed parse_options(const std::vector<std::string>& args) {
  Options o;
  Parsed out;
  const auto fail = [&](const std::string& why) {
    out.options.reset();
    out.status = 2;
    out.message = "cncd-fleet: " + why + "\n" + usage();
    return out;
  };
  std::string ini, password_file, broker, username, tls_ca, protocol;
  std::map<std::string, std::function<bool(const std::string&)>> with_value = {
      {"--listen",
       [&](const std::string& v) { return address_port(v, o.listen_address, o.listen_port); }},
      {"--www", [&](const std::string& v) { return o.www = v, !v.empty(); }},
      {"--ini", [&](const std::string& v) { return ini = v, !v.empty(); }},
      {"--broker", [&](const std::string& v) { return broker = v, !v.empty(); }},
      {"--username", [&](const std::string& v) { return username = v, true; }},
      {"--password-file", [&](const std::string& v) { return password_file = v, !v.empty(); }},
      {"--tls-ca", [&](const std::string& v) { return tls_ca = v, true; }},
      {"--protocol", [&](const std::string& v) { return protocol = v, v == "5" || v == "3.1.1"; }},
      {"--topics", [&](const std::string& v) { return o.pattern = v, check_pattern(v).empty(); }},
      {"--max-machines",
       [&](const std::string& v) {
         long long n = 0;
         return whole_number(v, 1, 1000000, n) && (o.limits.max_machines = n, true);
       }},
      {"--max-payload",
       [&](const std::string& v) {
         long long n = 0;
         return whole_number(v, 256, 256 << 20, n) && (o.limits.max_payload = n, true);
       }},
      {"--max-clients",
       [&](const std::string& v) {
         long long n = 0;
         return whole_number(v, 1, 10000, n) && (o.max_clients = n, true);
       }},
      {"--push-ms",
       [&](const std::string& v) {
         long long n = 0;
         return whole_number(v, 1, 10000, n) && (o.push_ms = static_cast<int>(n), true);
       }},
      {"--allowed-origin",
       [&](const std::string& v) { return o.allowed_origins.push_back(v), !v.empty(); }},
      {"--log-level", [&](const std::string& v) { return o.log_level = v, true; }},
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      out.status = 0;
      out.message = usage();
      return out;
    }
    const auto it = with_value.find(arg);
    if (it == with_value.end()) return fail("unknown option '" + arg + "'");
    if (i + 1 >= args.size()) return fail(arg + " needs a value");
    const std::string& value = args[++i];
    if (!it->second(value)) {
      if (arg == "--topics") return fail(check_pattern(value));
      if (arg == "--listen")
        return fail("'" + value + "' is not ADDRESS:PORT (e.g. 127.0.0.1:8090, [::1]:8090)");
      return fail("'" + value + "' is not a valid value for " + arg);
    }
  }
  if (!ini.empty()) {
    std::ostringstream problems;
    auto loaded = config::load_or_report(ini, "cncd-fleet", problems);
    if (!loaded) {
      out.status = config::kExitConfig;
      out.message = problems.str();
      return out;
    }
    o.broker = telemetry::broker_options(loaded->telemetry);
    if (o.broker.host.empty())
      return fail(ini + ": [TELEMETRY] MQTT_HOST is not set: no broker to read");
  }
  if (!broker.empty()) {
    const auto colon = broker.rfind(':');
    long long port = 1883;
    if (colon != std::string::npos && broker.find(']', colon) == std::string::npos &&
        std::count(broker.begin(), broker.end(), ':') == 1) {
      if (!whole_number(broker.substr(colon + 1), 1, 65535, port))
        return fail("'" + broker + "' is not HOST[:PORT]");
      broker = broker.substr(0, colon);
    }
    o.broker.host = broker;
    o.broker.port = static_cast<int>(port);
  }
  if (!username.empty()) o.broker.username = username;
  if (!tls_ca.empty()) o.broker.tls_ca = tls_ca;
  if (!protocol.empty()) o.broker.protocol = protocol == "5" ? 5 : 311;
  // systemd's LoadCredential=mqtt-password:FILE, when no file is named.
  if (const char* credentials = std::getenv("CREDENTIALS_DIRECTORY");
      password_file.empty() && credentials != nullptr &&
      std::filesystem::exists(std::filesystem::path(credentials) / "mqtt-password")) {
    password_file = (std::filesystem::path(credentials) / "mqtt-password").string();
  }
  if (!password_file.empty()) {
    std::ifstream in(password_file);
    std::string line;
    if (!in || !std::getline(in, line)) return fail("cannot read " + password_file);
    o.broker.password = line;
  }
  out.options = std::move(o);
  return out;
}

}  // namespace cncd::fleet
