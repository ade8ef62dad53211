#include "http_handlers.hpp"

#include <fcntl.h>
#include <sys/stat.h>

#include <array>
#include <chrono>
#include <utility>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

namespace cncd::web {
namespace {

using json = nlohmann::json;

// Without login: what the login page needs, nothing else.
constexpr std::array<std::string_view, 4> kPublicFiles = {"login.html", "login.js", "style.css",
                                                          "favicon.ico"};

// No Origin (curl, scripts), the page's own origin, or one of [WEB] ALLOWED_ORIGINS.
bool origin_allowed(const App& app, const RequestHeader& req, const Peer& peer) {
  return app.origin_allowed(req[http::field::origin], req[http::field::host], peer.tls);
}

std::string cookie(const std::string& value, bool tls, long max_age) {
  return "cncd_session=" + value +
         "; HttpOnly; SameSite=Strict; Path=/; Max-Age=" + std::to_string(max_age) +
         (tls ? "; Secure" : "");
}

double unix_seconds(std::chrono::system_clock::time_point t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}

http::message_generator redirect(const RequestHeader& req, std::string_view to) {
  http::response<http::empty_body> res{http::status::see_other, req.version()};
  res.set(http::field::location, to);
  res.set(http::field::cache_control, "no-store");
  res.prepare_payload();  // Content-Length: 0, or the client waits for the connection to end
  res.keep_alive(keeps_alive(req));
  return res;
}

json session_json(const Identity& who) {
  json methods = json::array();
  for (const auto& m : web::methods(who.role))
    methods.push_back(m);
  return {{"user", who.user}, {"role", role_name(who.role)}, {"methods", methods}};
}

void login(App& app, StringRequest&& req, const Peer& peer,
           std::function<void(http::message_generator)> done) {
  const json body = json::parse(req.body(), nullptr, false);
  if (!body.is_object() || !body.value("user", json()).is_string() ||
      !body.value("password", json()).is_string()) {
    return done(error_response(req, http::status::bad_request,
                               "the body must be JSON {\"user\": ..., \"password\": ...}"));
  }
  const std::string user = body["user"];
  if (const auto wait = app.limiter.retry_after(peer.address, user); wait.count() > 0) {
    auto res = error_response(
        req, http::status::too_many_requests,
        "too many failed logins; try again in " + std::to_string(wait.count()) + " s");
    res.set(http::field::retry_after, std::to_string(wait.count()));
    return done(std::move(res));
  }
  if (const auto problem = app.refresh_users(); !problem.empty()) spdlog::error("{}", problem);
  const User* known = app.users.find(user);
  std::string hash = known != nullptr ? known->password_hash : app.dummy_hash;
  const Role role = known != nullptr ? known->role : Role::observer;
  // argon2 takes a tenth of a second by design: never on the thread that forwards estops.
  boost::asio::post(app.workers, [&app, req = std::move(req), peer, user, role, known = !!known,
                                  hash = std::move(hash),
                                  password = body["password"].get<std::string>(),
                                  done = std::move(done)]() mutable {
    const bool ok = known && verify_password(hash, password);
    boost::asio::post(app.io, [&app, req = std::move(req), peer, user, role, ok,
                               done = std::move(done)]() mutable {
      if (!ok) {
        app.limiter.failed(peer.address, user);
        spdlog::warn("failed login for {} from {}", user, peer.address);
        return done(error_response(req, http::status::unauthorized, "wrong user or password"));
      }
      app.limiter.succeeded(user);
      const Session session = app.sessions.create(user, role, peer.address);
      spdlog::info("{} ({}) logged in from {}", user, role_name(role), peer.address);
      auto res = json_response(req, http::status::ok, {{"user", user}, {"role", role_name(role)}});
      res.set(http::field::set_cookie,
              cookie(session.token, peer.tls, static_cast<long>(app.web.session_hours) * 3600));
      done(std::move(res));
    });
  });
}

http::message_generator programs_list(App& app, const RequestHeader& req) {
  FileStatus status;
  const auto entries = app.programs.list(status);
  if (!entries) return error_response(req, http::status::internal_server_error, status.message);
  json list = json::array();
  for (const auto& e : *entries) {
    const auto estimate = app.estimates.get(app.programs.path() / e.name, e.size, e.mtime);
    list.push_back({{"name", e.name},
                    {"size", e.size},
                    {"mtime", unix_seconds(e.mtime)},
                    {"estimate_s", estimate ? json(*estimate) : json()}});
  }
  return json_response(req, http::status::ok, list);
}

}  // namespace

http::status status_of(FileError error) {
  switch (error) {
    case FileError::bad_name:
      return http::status::bad_request;
    case FileError::not_found:
      return http::status::not_found;
    case FileError::exists:
    case FileError::running:
      return http::status::conflict;
    case FileError::too_large:
      return http::status::payload_too_large;
    case FileError::not_regular:
    case FileError::outside:
      return http::status::forbidden;
    default:
      return http::status::internal_server_error;
  }
}

namespace {

http::message_generator download(App& app, const RequestHeader& req, std::string_view segment) {
  const auto decoded = percent_decode(segment);
  if (!decoded.ok()) return error_response(req, http::status::bad_request, decoded.error);
  if (auto why = check_program_name(decoded.text); !why.empty())
    return error_response(req, http::status::bad_request, why);
  FileStatus status;
  auto file = app.programs.open_for_read(decoded.text, status);
  if (!file) return error_response(req, status_of(status.error), status.message);
  http::file_body::value_type body;
  boost::beast::file f;
  boost::beast::error_code ec;
  f.native_handle(file->fd.release());
  body.reset(std::move(f), ec);
  if (ec) return error_response(req, http::status::internal_server_error, ec.message());
  http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                      std::make_tuple(http::status::ok, req.version())};
  res.set(http::field::content_type, "application/octet-stream");
  res.set(http::field::content_disposition, "attachment; filename=\"" + decoded.text + "\"");
  res.set(http::field::cache_control, "no-store");
  secure_headers(res.base());
  res.content_length(static_cast<std::uint64_t>(file->size));
  res.keep_alive(keeps_alive(req));
  return res;
}

}  // namespace

void handle_request(App& app, StringRequest&& req, const Peer& peer,
                    std::function<void(http::message_generator)> done) {
  const std::string_view path = target_path(req);
  const auto verb = req.method();
  const bool changes = verb != http::verb::get && verb != http::verb::head;
  if (changes && !origin_allowed(app, req, peer))
    return done(error_response(
        req, http::status::forbidden,
        "origin " + std::string(req[http::field::origin]) + " may not change anything here"));
  if (path == "/api/login") {
    if (verb != http::verb::post)
      return done(error_response(req, http::status::method_not_allowed, "POST only"));
    return login(app, std::move(req), peer, std::move(done));
  }
  const auto who = app.identify(req[http::field::cookie], req[http::field::authorization]);
  if (path == "/api/logout") {
    if (verb != http::verb::post)
      return done(error_response(req, http::status::method_not_allowed, "POST only"));
    if (who && !who->by_key) {
      app.sessions.drop(who->session.token);
      app.sessions_dropped({who->session.id});
    }
    auto res = json_response(req, http::status::ok, {{"ok", true}});
    res.set(http::field::set_cookie, cookie("", peer.tls, 0));
    return done(std::move(res));
  }
  if (path.starts_with("/api/")) {
    if (!who) return done(error_response(req, http::status::unauthorized, "log in first"));
    if (path == "/api/session" && verb == http::verb::get)
      return done(json_response(req, http::status::ok, session_json(*who)));
    if (path == "/api/programs" && verb == http::verb::get) return done(programs_list(app, req));
    if (path.starts_with("/api/programs/") && verb == http::verb::get)
      return done(download(app, req, path.substr(std::string_view("/api/programs/").size())));
    return done(error_response(req, http::status::not_found, "no such API: " + std::string(path)));
  }
  if (verb != http::verb::get && verb != http::verb::head)
    return done(error_response(req, http::status::method_not_allowed, "GET only"));
  if (path == "/" || path == "/index.html") {
    if (!who) return done(redirect(req, "/login.html"));
    return done(serve_file(app.www_dir, req, "index.html"));
  }
  const auto relative = static_path(path);
  if (!relative) return done(error_response(req, http::status::not_found, "no such file"));
  const bool is_public =
      std::find(kPublicFiles.begin(), kPublicFiles.end(), *relative) != kPublicFiles.end();
  if (!is_public && !who)
    return done(error_response(req, http::status::unauthorized, "log in first"));
  done(serve_file(app.www_dir, req, *relative));
}

UploadCheck check_upload(App& app, const RequestHeader& req, const Peer& peer) {
  UploadCheck check;
  if (!origin_allowed(app, req, peer)) {
    check.refusal =
        error_response(req, http::status::forbidden,
                       "origin " + std::string(req[http::field::origin]) + " may not upload here");
    return check;
  }
  const auto who = app.identify(req[http::field::cookie], req[http::field::authorization]);
  if (!who) {
    check.refusal = error_response(req, http::status::unauthorized, "log in first");
    return check;
  }
  if (!allowed(who->role, kUploadMethod)) {
    check.refusal =
        error_response(req, http::status::forbidden, refusal_message(kUploadMethod, who->role));
    return check;
  }
  const auto segment = target_path(req).substr(std::string_view("/api/programs/").size());
  const auto decoded = percent_decode(segment);
  std::string why = decoded.ok() ? check_program_name(decoded.text) : decoded.error;
  if (!why.empty()) {
    check.refusal = error_response(req, http::status::bad_request, why);
    return check;
  }
  if (const auto length = req[http::field::content_length]; !length.empty()) {
    const auto bytes = std::strtoll(std::string(length).c_str(), nullptr, 10);
    if (bytes > app.programs.max_upload_bytes()) {
      check.refusal = error_response(req, http::status::payload_too_large,
                                     "the program is over the limit of " +
                                         std::to_string(app.programs.max_upload_bytes() >> 20) +
                                         " MB ([WEB] MAX_UPLOAD_MB)");
      return check;
    }
  }
  check.name = decoded.text;
  check.user = who->user;
  return check;
}

UpgradeCheck check_upgrade(App& app, const RequestHeader& req, const Peer& peer) {
  UpgradeCheck check;
  if (!origin_allowed(app, req, peer)) {
    check.refusal = error_response(
        req, http::status::forbidden,
        "origin " + std::string(req[http::field::origin]) + " may not open a WebSocket here");
    return check;
  }
  auto who = app.identify(req[http::field::cookie], req[http::field::authorization]);
  if (!who) {
    check.refusal = error_response(req, http::status::unauthorized, "log in first");
    return check;
  }
  if (app.peers.size() >= static_cast<std::size_t>(app.web.max_clients)) {
    check.refusal = error_response(req, http::status::service_unavailable,
                                   "too many WebSocket clients ([WEB] MAX_CLIENTS = " +
                                       std::to_string(app.web.max_clients) + ")");
    return check;
  }
  check.identity = std::move(*who);
  return check;
}

}  // namespace cncd::web
