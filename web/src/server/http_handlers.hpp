// The HTTP surface apart from the transport: static files, login, session, the programs API
// and the checks an upload or a WebSocket upgrade must pass. Transport-independent, so plain
// and TLS connections share it (http_session.hpp holds the stream-specific part).
#pragma once

#include <functional>
#include <optional>
#include <string>

#include <boost/beast/http.hpp>

#include "app.hpp"
#include "http_common.hpp"

namespace cncd::web {

// The connection a request came on.
struct Peer {
  std::string address;  // remote IP address, as written in logs and the event log
  bool tls = false;
};

// The HTTP status a refused file operation is answered with.
http::status status_of(FileError error);

// Handles a request read whole; `done` gets the answer, now or (login: after argon2 on a
// worker thread) later, on the I/O thread.
void handle_request(App& app, StringRequest&& req, const Peer& peer,
                    std::function<void(http::message_generator)> done);

// An upload, PUT /api/programs/NAME, may go ahead: the identity and the decoded name; else
// the refusal to send (and the body is not read).
struct UploadCheck {
  std::optional<StringResponse> refusal;
  std::string name;
  std::string user;
};
UploadCheck check_upload(App& app, const RequestHeader& req, const Peer& peer);

// A WebSocket upgrade on /ws may go ahead: the identity; else the refusal.
struct UpgradeCheck {
  std::optional<StringResponse> refusal;
  Identity identity;
};
UpgradeCheck check_upgrade(App& app, const RequestHeader& req, const Peer& peer);

}  // namespace cncd::web
