// [WEB]: cncd-web's keys. cncd reads them too (cncd-check and the daemon see one file), but
// only checks them: they describe another process.
#include <arpa/inet.h>

#include <algorithm>
#include <string>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

void load_listen(TypedReader& r, WebConfig& web) {
  const std::string listen(trim(strip_trailing_comment(r.text("WEB", "LISTEN").value_or(""))));
  if (listen.empty()) {
    r.problem("WEB", "LISTEN", "empty; give an address such as 127.0.0.1, 0.0.0.0 or ::");
  } else if (const auto address = ip_address(listen)) {
    web.listen = *address;
  } else {
    r.problem(
        "WEB", "LISTEN",
        "'" + printable(listen) + "' is not an IP address (e.g. 127.0.0.1, 0.0.0.0, ::1 or ::)");
  }
}

// The first program directory when not given; otherwise it must be one of them, so that a
// program uploaded through the web can be opened.
void load_program_dir(TypedReader& r, const MachineConfig& c, WebConfig& web) {
  const auto given = r.path("WEB", "PROGRAM_DIR");
  if (!given || given->empty()) {
    if (!c.program_dirs.empty()) web.program_dir = c.program_dirs.front();
    return;
  }
  std::filesystem::path dir = std::filesystem::absolute(*given).lexically_normal();
  if (!dir.has_filename() && dir.has_relative_path()) dir = dir.parent_path();
  if (std::find(c.program_dirs.begin(), c.program_dirs.end(), dir) == c.program_dirs.end()) {
    std::string dirs;
    for (const auto& d : c.program_dirs)
      dirs += (dirs.empty() ? "" : ", ") + d.string();
    r.problem("WEB", "PROGRAM_DIR",
              "'" + printable(dir.string()) +
                  "' is not one of cncd's program directories ([DISPLAY] PROGRAM_PREFIX, "
                  "[CNCD] PROGRAM_DIRS): " +
                  dirs);
    return;
  }
  web.program_dir = dir;
}

// Like the state files: a relative name lives in the state directory.
void load_users_file(TypedReader& r, const MachineConfig& c, WebConfig& web) {
  const std::string text(trim(r.text("WEB", "USERS_FILE").value_or("")));
  const std::filesystem::path given = text.empty() ? "web-users" : text;
  if (given.is_absolute()) {
    web.users_file = given.lexically_normal();
  } else if (!c.cncd.state_dir.empty()) {
    web.users_file = (c.cncd.state_dir / given).lexically_normal();
  } else if (!text.empty()) {
    r.problem("WEB", "USERS_FILE",
              "a relative path needs a state directory: set [CNCD] STATE_DIR (none of "
              "$STATE_DIRECTORY, $XDG_STATE_HOME and $HOME is set)");
  }
}

void load_tls(TypedReader& r, WebConfig& web) {
  web.tls_cert = r.path("WEB", "TLS_CERT").value_or("");
  web.tls_key = r.path("WEB", "TLS_KEY").value_or("");
  if (web.tls_cert.empty() != web.tls_key.empty()) {
    const bool cert = !web.tls_cert.empty();
    r.problem("WEB", cert ? "TLS_CERT" : "TLS_KEY",
              std::string(cert ? "TLS_KEY" : "TLS_CERT") +
                  " is missing: TLS needs both the certificate and its key");
  }
}

// "" when `origin` is scheme://host[:port] as a browser sends it, else why not.
std::string check_origin(std::string_view origin) {
  std::string_view rest;
  if (origin.starts_with("http://")) {
    rest = origin.substr(7);
  } else if (origin.starts_with("https://")) {
    rest = origin.substr(8);
  } else {
    return "does not start with http:// or https://";
  }
  if (rest.empty()) return "has no host";
  if (rest.find_first_of("/?#@") != std::string_view::npos) {
    return "has more than scheme://host[:port] (a browser sends no path, not even '/')";
  }
  const std::size_t colon = rest.rfind(':');
  if (colon != std::string_view::npos && rest.find(']', colon) == std::string_view::npos) {
    const std::string_view port = rest.substr(colon + 1);
    if (port.empty() || port.size() > 5 ||
        port.find_first_not_of("0123456789") != std::string_view::npos ||
        std::stoi(std::string(port)) > 65535) {
      return "has a port that is not 1..65535";
    }
  }
  return "";
}

void load_origins(TypedReader& r, WebConfig& web) {
  const std::string text(strip_trailing_comment(r.text("WEB", "ALLOWED_ORIGINS").value_or("")));
  std::string_view rest = text;
  while (true) {
    const std::size_t start = rest.find_first_not_of(" \t,");
    if (start == std::string_view::npos) break;
    rest.remove_prefix(start);
    const std::size_t end = std::min(rest.find_first_of(" \t,"), rest.size());
    const std::string_view origin = rest.substr(0, end);
    rest.remove_prefix(end);
    if (const std::string why = check_origin(origin); !why.empty()) {
      r.problem("WEB", "ALLOWED_ORIGINS", "'" + printable(origin) + "' " + why);
      continue;
    }
    web.allowed_origins.emplace_back(origin);
  }
}

}  // namespace

std::optional<std::string> ip_address(std::string_view text) {
  std::string address(text);
  if (address.size() > 2 && address.front() == '[' && address.back() == ']') {
    address = address.substr(1, address.size() - 2);
  }
  unsigned char buffer[16];
  if (::inet_pton(AF_INET, address.c_str(), buffer) != 1 &&
      ::inet_pton(AF_INET6, address.c_str(), buffer) != 1) {
    return std::nullopt;
  }
  return address;
}

void load_web(TypedReader& r, MachineConfig& c) {
  WebConfig& web = c.web;
  load_listen(r, web);
  if (const auto v = r.integer("WEB", "PORT")) web.port = static_cast<int>(*v);
  load_program_dir(r, c, web);
  if (const auto v = r.integer("WEB", "MAX_UPLOAD_MB")) web.max_upload_bytes = *v << 20;
  load_users_file(r, c, web);
  load_tls(r, web);
  load_origins(r, web);
  if (const auto v = r.integer("WEB", "SESSION_HOURS")) web.session_hours = static_cast<int>(*v);
  if (const auto v = r.integer("WEB", "MAX_CLIENTS")) web.max_clients = static_cast<int>(*v);
  if (const auto v = r.real("WEB", "JOG_HEARTBEAT")) web.jog_heartbeat_s = *v;
  refuse_unknown_keys(r, "WEB", "cncd-web's section");
}

}  // namespace cncd::config
