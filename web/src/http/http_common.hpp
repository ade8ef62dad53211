// What cncd's HTTP servers (cncd-web, cncd-fleet) share apart from their routes: JSON and error
// answers, static files from a page directory with safe headers, and reading a request target.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <boost/beast/http.hpp>
#include <nlohmann/json.hpp>

namespace cncd::web {

namespace http = boost::beast::http;
using StringRequest = http::request<http::string_body>;
using StringResponse = http::response<http::string_body>;
using RequestHeader = http::request_header<>;

// A JSON answer {"error": message} (or `body` when given) with `status`.
StringResponse json_response(const RequestHeader& req, http::status status,
                             const nlohmann::json& body);
StringResponse error_response(const RequestHeader& req, http::status status,
                              const std::string& message);

// Serves `www_dir`/`relative` (segments already checked, see static_path), or 404; revalidated
// on every load (Last-Modified, no-cache), so that after an upgrade page and scripts agree.
http::message_generator serve_file(const std::filesystem::path& www_dir, const RequestHeader& req,
                                   const std::string& relative);
// A request path's segments decoded and checked like program names (no "..", no hidden
// files), joined by '/'; nullopt when one is not acceptable.
std::optional<std::string> static_path(std::string_view path);
// nosniff, no framing, no referrer.
void secure_headers(http::fields& fields);

// An Origin header that may open a WebSocket or change things: none (curl, scripts), the
// page's own ("http(s)://" + Host) or one of `allowed` ("scheme://host[:port]"), any case.
bool origin_allowed(std::string_view origin, std::string_view host, bool secure,
                    const std::vector<std::string>& allowed);

// True when the client keeps the connection after the answer (HTTP/1.1 unless "close").
bool keeps_alive(const RequestHeader& req);
// True when the target's path (without query) is `path`.
bool target_is(const RequestHeader& req, std::string_view path);
// The path of a request target, without the query.
std::string_view target_path(const RequestHeader& req);

}  // namespace cncd::web
