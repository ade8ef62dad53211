#include "ws_rpc.hpp"

#include <algorithm>
#include <cctype>

namespace cncd::web {
namespace {

using json = nlohmann::json;

constexpr int kParseError = -32700;
constexpr int kInvalidRequest = -32600;
// As cncd: printing or copying a value recurses once per level, and a 1 MiB frame of brackets
// would exhaust the stack. Checked by a SAX pass that builds nothing and stops at the limit.
constexpr std::size_t kMaxNesting = 64;

class DepthCheck : public json::json_sax_t {
 public:
  bool too_deep = false;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return open(); }
  bool key(string_t&) override { return true; }
  bool end_object() override { return close(); }
  bool start_array(std::size_t) override { return open(); }
  bool end_array() override { return close(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  bool open() {
    too_deep = ++depth_ > kMaxNesting;
    return !too_deep;
  }
  bool close() {
    --depth_;
    return true;
  }
  std::size_t depth_ = 0;
};
constexpr int kMethodNotFound = -32601;
constexpr int kInvalidParams = -32602;

bool is_web_method(std::string_view method) {
  return method == "web.session" || method.starts_with("lease.") || method.starts_with("files.") ||
         method.starts_with("users.");
}

// Methods that only read: they go on without attribution, which cncd accepts only from
// control peers.
bool only_reads(std::string_view method) {
  return required_role(method) == Role::observer && method != "machine.estop";
}

std::string dump(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

std::string upper(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return text;
}

}  // namespace

json rpc_error(const json& id, int code, const std::string& message) {
  return {{"jsonrpc", "2.0"}, {"id", id}, {"error", {{"code", code}, {"message", message}}}};
}

WsRpc::WsRpc(App& app, Identity who, std::string address)
    : app_(app), who_(std::move(who)), address_(std::move(address)) {}

WsRpc::Output WsRpc::on_client(std::string_view text) {
  Output out;
  DepthCheck depth;
  json::sax_parse(text, &depth);
  if (depth.too_deep) {
    out.to_client.push_back(
        dump(rpc_error(nullptr, kInvalidRequest,
                       "request nested deeper than " + std::to_string(kMaxNesting) + " levels")));
    return out;
  }
  json message = json::parse(text, nullptr, false);
  if (message.is_discarded()) {
    out.to_client.push_back(dump(rpc_error(nullptr, kParseError, "parse error: not valid JSON")));
    return out;
  }
  if (!message.is_array() || message.empty()) {
    const json id = message.is_object() ? message.value("id", json()) : json();
    const bool notification = !message.is_object() || !message.contains("id");
    Handled h = handle(std::move(message));
    if (!h.answer.is_null()) out.to_client.push_back(dump(h.answer));
    if (!h.forward.is_null()) out.to_daemon.push_back(dump(h.forward));
    if (later_finish_) {
      out.later = Later{std::move(later_work_),
                        [finish = std::move(*later_finish_), id, notification](std::string done) {
                          json answer;
                          try {
                            answer = {{"jsonrpc", "2.0"}, {"id", id}, {"result", finish(done)}};
                          } catch (const WebError& e) {
                            answer = rpc_error(id, e.code, e.message);
                          }
                          return notification ? std::string() : dump(answer);
                        }};
      later_finish_.reset();
    }
    return out;
  }
  // A batch: each request checked on its own. Those answered here come back as one batch,
  // those for cncd go on as another, and cncd answers them as one.
  json answers = json::array();
  json forward = json::array();
  for (auto& request : message) {
    if (request.is_object() && (request.value("method", json()) == "users.add" ||
                                request.value("method", json()) == "users.passwd")) {
      answers.push_back(rpc_error(
          request.value("id", json()), kInvalidRequest,
          "send " + request["method"].get<std::string>() + " on its own, not in a batch"));
      continue;
    }
    Handled h = handle(std::move(request));
    if (!h.answer.is_null()) answers.push_back(std::move(h.answer));
    if (!h.forward.is_null()) forward.push_back(std::move(h.forward));
  }
  if (!answers.empty()) out.to_client.push_back(dump(answers));
  if (!forward.empty()) out.to_daemon.push_back(dump(forward));
  return out;
}

WsRpc::Handled WsRpc::handle(json request) {
  Handled h;
  const auto method_it = request.is_object() ? request.find("method") : request.end();
  if (!request.is_object() || method_it == request.end() || !method_it->is_string()) {
    h.forward = std::move(request);  // malformed: cncd answers it as it answers anyone
    return h;
  }
  const bool notification = !request.contains("id");
  const json id = request.value("id", json());
  const std::string method = *method_it;
  const auto refuse = [&](int code, const std::string& message) {
    if (!notification) h.answer = rpc_error(id, code, message);
    return h;
  };
  if (!required_role(method)) return refuse(kMethodNotFound, "unknown method \"" + method + "\"");
  if (!allowed(who_.role, method)) return refuse(kRoleRefused, refusal_message(method, who_.role));
  if (needs_lease(method) && !app_.lease.held_by(who_.session.id)) {
    const auto holder = app_.lease.holder();
    return refuse(kLeaseRefused, method + " needs the control lease, held by " +
                                     (holder ? holder->user + " at " + holder->address
                                             : std::string("nobody (take it with lease.take)")));
  }
  json params = request.value("params", json::object());
  if (is_web_method(method)) {
    try {
      json forward;
      json result = web_method(method, params, forward);
      if (later_finish_) return h;  // answered when the worker is done
      if (!forward.is_null()) {
        if (!notification) forward["id"] = id;
        request = std::move(forward);  // files.open: becomes program.open
        params = request["params"];
      } else {
        if (!notification) h.answer = {{"jsonrpc", "2.0"}, {"id", id}, {"result", result}};
        return h;
      }
    } catch (const WebError& e) {
      return refuse(e.code, e.message);
    }
  }
  const std::string sent = request["method"];
  if (sent == "program.open") {
    if (!params.is_object() || !params.value("path", json()).is_string())
      return refuse(kInvalidParams, "program.open needs {\"path\": NAME}, a program's name");
    FileStatus status;
    const std::string name = params["path"];
    const auto path = app_.programs.resolve(name, status);
    if (!path) return refuse(kInvalidParams, status.message);
    request["params"]["path"] = path->string();
  }
  if (sent == "jog.start" && params.is_object() && params.value("axis", json()).is_string()) {
    jogging_.insert(upper(params["axis"]));
    // A page that stops sending jog.heartbeat (tab closed, network lost, browser frozen) stops
    // the jog this long after: cncd does it, also when cncd-web itself is gone.
    request["params"]["heartbeat_s"] = app_.web.jog_heartbeat_s;
  }
  if (sent == "jog.stop" && params.is_object() && params.value("axis", json()).is_string())
    jogging_.erase(upper(params["axis"]));
  if (!only_reads(sent))
    request["on_behalf_of"] = {{"user", who_.user}, {"address", address_}, {"via", "web"}};
  h.forward = std::move(request);
  return h;
}

std::vector<std::string> WsRpc::on_close() {
  std::vector<std::string> lines;
  for (const auto& axis : jogging_) {
    json stop = {{"jsonrpc", "2.0"}, {"method", "jog.stop"}, {"params", {{"axis", axis}}}};
    stop["on_behalf_of"] = {{"user", who_.user}, {"address", address_}, {"via", "web"}};
    lines.push_back(dump(stop));
  }
  jogging_.clear();
  return lines;
}

}  // namespace cncd::web
