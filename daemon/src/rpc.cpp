#include "rpc.hpp"

#include <exception>
#include <string>

namespace cncd::daemon {

using nlohmann::json;

void RpcDispatcher::add(const std::string& method, Handler handler, Access needs) {
  handlers_[method] = Entry{std::move(handler), needs};
}

void RpcDispatcher::add(const std::string& method, SimpleHandler handler, Access needs) {
  add(
      method, [h = std::move(handler)](const json& params, Session&) { return h(params); }, needs);
}

json RpcDispatcher::error_object(int code, const std::string& message) {
  return json{{"code", code}, {"message", message}};
}

namespace {
// Deeper nesting is refused before parsing: copying or printing such a value recurses once per
// level, and a 1 MiB line of brackets would exhaust the stack.
constexpr int kMaxNesting = 64;
// A longer batch would be answered in one piece, holding up every other client meanwhile.
constexpr std::size_t kMaxBatch = 256;

bool nested_too_deep(const std::string& line) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

json error_response(const json& id, int code, const std::string& message) {
  return json{
      {"jsonrpc", "2.0"}, {"id", id}, {"error", RpcDispatcher::error_object(code, message)}};
}
}  // namespace

std::optional<json> RpcDispatcher::handle_one(const json& request, Session& session) const {
  if (!request.is_object())
    return error_response(nullptr, kInvalidRequest, "request must be an object");
  json id = nullptr;
  const bool notification = !request.contains("id");
  if (!notification) {
    id = request["id"];
    if (!(id.is_null() || id.is_string() || id.is_number())) {
      return error_response(nullptr, kInvalidRequest, "id must be a string, a number or null");
    }
  }
  auto reply_error = [&](int code, const std::string& message) -> std::optional<json> {
    if (notification) return std::nullopt;
    return error_response(id, code, message);
  };
  if (request.value("jsonrpc", json()) != "2.0") {
    return reply_error(kInvalidRequest, "\"jsonrpc\" must be \"2.0\"");
  }
  const auto method = request.find("method");
  if (method == request.end() || !method->is_string()) {
    return reply_error(kInvalidRequest, "\"method\" must be a string");
  }
  json params = request.value("params", json());
  if (!(params.is_null() || params.is_object() || params.is_array())) {
    return reply_error(kInvalidParams, "\"params\" must be an object or an array");
  }
  const auto handler = handlers_.find(method->get<std::string>());
  if (handler == handlers_.end()) {
    return reply_error(kMethodNotFound, "unknown method '" + method->get<std::string>() + "'");
  }
  if (session.access < handler->second.needs) {
    return reply_error(kPermissionDenied, "permission denied: '" + method->get<std::string>() +
                                              "' needs the control group");
  }
  try {
    session.defer_token = 0;
    json result = handler->second.handler(params, session);
    if (session.defer_token != 0) {
      if (!notification) session.open_requests.emplace_back(session.defer_token, id);
      session.defer_token = 0;
      return std::nullopt;
    }
    if (notification) return std::nullopt;
    return json{{"jsonrpc", "2.0"}, {"id", id}, {"result", std::move(result)}};
  } catch (const RpcError& e) {
    return reply_error(e.code(), e.what());
  } catch (const json::exception& e) {
    return reply_error(kInvalidParams, std::string("invalid params: ") + e.what());
  } catch (const std::exception& e) {
    return reply_error(kInternalError, e.what());
  }
}

std::optional<std::string> RpcDispatcher::handle_line(const std::string& line,
                                                      Session& session) const {
  if (nested_too_deep(line)) {
    return error_response(nullptr, kInvalidRequest,
                          "request nested deeper than " + std::to_string(kMaxNesting) + " levels")
        .dump();
  }
  json request = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (request.is_discarded()) {
    return error_response(nullptr, kParseError, "parse error: not valid JSON").dump();
  }
  if (request.is_array()) {
    if (request.empty()) return error_response(nullptr, kInvalidRequest, "empty batch").dump();
    if (request.size() > kMaxBatch) {
      return error_response(nullptr, kInvalidRequest,
                            "a batch may hold at most " + std::to_string(kMaxBatch) + " requests")
          .dump();
    }
    json responses = json::array();
    session.in_batch = true;
    for (const auto& one : request) {
      if (auto response = handle_one(one, session)) responses.push_back(std::move(*response));
    }
    session.in_batch = false;
    if (responses.empty()) return std::nullopt;
    return responses.dump(-1, ' ', false, json::error_handler_t::replace);
  }
  auto response = handle_one(request, session);
  if (!response) return std::nullopt;
  return response->dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace cncd::daemon
