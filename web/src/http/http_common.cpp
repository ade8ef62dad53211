#include "http_common.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <ctime>
#include <utility>

#include "cncd/web/program_dir.hpp"

namespace cncd::web {
namespace {

using json = nlohmann::json;

std::string_view content_type(std::string_view name) {
  static const std::array<std::pair<std::string_view, std::string_view>, 12> types = {{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".ico", "image/x-icon"},
      {".woff2", "font/woff2"},
      {".txt", "text/plain; charset=utf-8"},
      {".md", "text/plain; charset=utf-8"},
      {".map", "application/json"},
  }};
  for (const auto& [ext, type] : types) {
    if (name.size() >= ext.size() && name.substr(name.size() - ext.size()) == ext) return type;
  }
  return "application/octet-stream";
}

std::string http_date(std::chrono::system_clock::time_point t) {
  const std::time_t seconds = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char text[64];
  std::strftime(text, sizeof text, "%a, %d %b %Y %H:%M:%S GMT", &tm);
  return text;
}

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

}  // namespace

bool origin_allowed(std::string_view origin, std::string_view host, bool secure,
                    const std::vector<std::string>& allowed) {
  if (origin.empty()) return true;
  if (lower(origin) == lower(std::string(secure ? "https://" : "http://") + std::string(host)))
    return true;
  return std::any_of(allowed.begin(), allowed.end(),
                     [&](const std::string& one) { return lower(one) == lower(origin); });
}

void secure_headers(http::fields& fields) {
  fields.set("X-Content-Type-Options", "nosniff");
  fields.set("X-Frame-Options", "DENY");
  fields.set("Referrer-Policy", "no-referrer");
}

http::message_generator serve_file(const std::filesystem::path& www_dir, const RequestHeader& req,
                                   const std::string& relative) {
  const auto path = www_dir / relative;
  struct stat st {};
  if (stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
    return error_response(req, http::status::not_found, "no such file: /" + relative);
  const auto mtime = std::chrono::system_clock::from_time_t(st.st_mtime);
  const std::string modified = http_date(mtime);
  if (req[http::field::if_modified_since] == modified) {
    http::response<http::empty_body> res{http::status::not_modified, req.version()};
    res.set(http::field::cache_control, "no-cache");
    res.set(http::field::last_modified, modified);
    res.keep_alive(keeps_alive(req));
    // 304 has no body by definition: no Content-Length needed.
    return res;
  }
  http::file_body::value_type body;
  boost::beast::error_code ec;
  body.open(path.c_str(), boost::beast::file_mode::scan, ec);
  if (ec) return error_response(req, http::status::not_found, "cannot read /" + relative);
  const auto size = body.size();
  http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                      std::make_tuple(http::status::ok, req.version())};
  res.set(http::field::content_type, content_type(relative));
  // Revalidated on every load: after an upgrade the page and its scripts agree.
  res.set(http::field::cache_control, "no-cache");
  res.set(http::field::last_modified, modified);
  secure_headers(res.base());
  res.content_length(size);
  res.keep_alive(keeps_alive(req));
  if (req.method() == http::verb::head) {
    http::response<http::empty_body> head{http::status::ok, req.version()};
    head.base() = res.base();
    return head;
  }
  return res;
}

std::optional<std::string> static_path(std::string_view path) {
  std::string relative;
  while (!path.empty()) {
    path.remove_prefix(1);  // the '/'
    const auto end = path.find('/');
    const auto decoded = percent_decode(path.substr(0, end));
    if (!decoded.ok() || !check_program_name(decoded.text).empty()) return std::nullopt;
    relative += (relative.empty() ? "" : "/") + decoded.text;
    path = end == std::string_view::npos ? std::string_view() : path.substr(end);
  }
  return relative;
}

StringResponse json_response(const RequestHeader& req, http::status status, const json& body) {
  StringResponse res{status, req.version()};
  res.set(http::field::content_type, "application/json");
  res.set(http::field::cache_control, "no-store");
  secure_headers(res.base());
  res.body() = body.dump(-1, ' ', false, json::error_handler_t::replace);
  res.prepare_payload();
  res.keep_alive(keeps_alive(req));
  return res;
}

StringResponse error_response(const RequestHeader& req, http::status status,
                              const std::string& message) {
  return json_response(req, status, {{"error", message}});
}

bool keeps_alive(const RequestHeader& req) {
  http::token_list connection{req[http::field::connection]};
  return req.version() >= 11 ? !connection.exists("close") : connection.exists("keep-alive");
}

std::string_view target_path(const RequestHeader& req) {
  const std::string_view target = req.target();
  return target.substr(0, target.find('?'));
}

bool target_is(const RequestHeader& req, std::string_view path) {
  return target_path(req) == path;
}

}  // namespace cncd::web
