#include "rpc.hpp"

#include <algorithm>
#include <cstdint>
#include <exception>
#include <iterator>
#include <set>
#include <string>

#include <spdlog/spdlog.h>

#include "attribution.hpp"
#include "event_log.hpp"

namespace cncd::daemon {

using nlohmann::json;

RpcDispatcher::RpcDispatcher() : RpcDispatcher(method_table()) {}

RpcDispatcher::RpcDispatcher(std::vector<MethodSpec> table) {
  for (auto& spec : table) {
    const std::string name(spec.name);
    if (!table_.emplace(name, std::move(spec)).second) {
      throw std::logic_error("method table lists '" + name + "' twice");
    }
  }
}

void RpcDispatcher::add(const std::string& method, Handler handler,
                        const std::vector<Range>& ranges) {
  const auto spec = table_.find(method);
  if (spec == table_.end()) {
    throw std::logic_error("method '" + method + "' is not in the method table");
  }
  if (handlers_.contains(method)) throw std::logic_error("method '" + method + "' added twice");
  MethodSpec bound = spec->second;
  for (const auto& range : ranges) {
    const auto param = std::find_if(bound.params.begin(), bound.params.end(),
                                    [&](const ParamSpec& p) { return p.name == range.param; });
    if (param == bound.params.end() ||
        !(param->type == ParamType::number || param->type == ParamType::integer ||
          param->type == ParamType::integer_list)) {
      throw std::logic_error("method '" + method + "' has no number parameter '" +
                             std::string(range.param) + "'");
    }
    param->min = range.min;
    param->max = range.max;
  }
  handlers_.emplace(method, Entry{std::move(handler), nullptr, std::move(bound)});
}

void RpcDispatcher::add(const std::string& method, SimpleHandler handler,
                        const std::vector<Range>& ranges) {
  add(
      method, [h = std::move(handler)](const json& params, Session&) { return h(params); }, ranges);
}

void RpcDispatcher::add_raw(const std::string& method, RawHandler handler) {
  add(method, [](const json&, Session&) { return json(); });
  handlers_.find(method)->second.raw = std::move(handler);
}

void RpcDispatcher::require_all_added() const {
  std::string missing;
  for (const auto& [name, spec] : table_) {
    if (!handlers_.contains(name)) missing += (missing.empty() ? "" : ", ") + name;
  }
  if (!missing.empty()) throw std::logic_error("methods without a handler: " + missing);
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
// Of a command's parameters, as much is recorded in its event.
constexpr std::size_t kRecordedParamsBytes = 200;

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

std::string text_of(const json& value) {
  return value.dump(-1, ' ', false, json::error_handler_t::replace);
}

json error_response(const json& id, int code, const std::string& message) {
  return json{
      {"jsonrpc", "2.0"}, {"id", id}, {"error", RpcDispatcher::error_object(code, message)}};
}
}  // namespace

std::optional<std::string> RpcDispatcher::handle_one(const json& request, Session& session,
                                                     const RepeatedKey* repeated) const {
  if (!request.is_object())
    return text_of(error_response(nullptr, kInvalidRequest, "request must be an object"));
  json id = nullptr;
  const bool notification = !request.contains("id");
  if (!notification && !(repeated != nullptr && repeated->id)) {
    id = request["id"];
    if (!(id.is_null() || id.is_string() || id.is_number())) {
      return text_of(
          error_response(nullptr, kInvalidRequest, "id must be a string, a number or null"));
    }
  }
  auto reply_error = [&](int code, const std::string& message) -> std::optional<std::string> {
    if (notification) return std::nullopt;
    return text_of(error_response(id, code, message));
  };
  if (repeated != nullptr) {
    return reply_error(kInvalidRequest, "duplicate key " + quoted_text(repeated->key) +
                                            ": a request names each key of an object once");
  }
  if (request.value("jsonrpc", json()) != "2.0") {
    return reply_error(kInvalidRequest, "\"jsonrpc\" must be \"2.0\"");
  }
  const auto method = request.find("method");
  if (method == request.end() || !method->is_string()) {
    return reply_error(kInvalidRequest, "\"method\" must be a string");
  }
  const std::string& name = method->get_ref<const std::string&>();
  std::optional<Attribution> on_behalf;
  if (const auto member = request.find("on_behalf_of"); member != request.end()) {
    if (session.access != Access::control) {
      return reply_error(kAttributionRefused,
                         "permission denied: \"on_behalf_of\" is accepted only from root, cncd's "
                         "own user or the control group, and " +
                             (session.peer.empty() ? std::string("this peer") : session.peer) +
                             " may only read");
    }
    auto parsed = parse_attribution(*member);
    if (const auto* error = std::get_if<std::string>(&parsed)) {
      return reply_error(kInvalidRequest, *error);
    }
    on_behalf = std::move(std::get<Attribution>(parsed));
  }
  const auto handler = handlers_.find(name);
  if (handler == handlers_.end()) {
    return reply_error(kMethodNotFound, "unknown method " + quoted_text(name));
  }
  const Entry& entry = handler->second;
  if (session.access < entry.spec.needs) {
    return reply_error(kPermissionDenied,
                       "permission denied: " + quoted_text(name) + " needs the control group");
  }
  const auto given = request.find("params");
  auto checked = check_params(entry.spec, given == request.end() ? nullptr : &*given);
  if (const auto* error = std::get_if<std::string>(&checked)) {
    return reply_error(kInvalidParams, *error);
  }
  const json& params = std::get<json>(checked);
  const bool command = entry.spec.needs == Access::control;
  // Also when the handler throws: a refused command may have changed the state on its way.
  struct AfterCommand {
    const std::function<void()>* hook;
    EventLog* events;
    ~AfterCommand() {
      if (events != nullptr) events->set_actor("");
      if (hook != nullptr && *hook) (*hook)();
    }
  } after{command ? &after_command_ : nullptr, command ? events_ : nullptr};
  const std::string actor = on_behalf ? attribution_text(*on_behalf, session.peer) : session.peer;
  if (after.events != nullptr) after.events->set_actor(actor);
  std::string refused;  // the handler's error
  auto outcome = [&]() -> std::optional<std::string> {
    try {
      session.defer_token = 0;
      if (entry.raw) {
        std::string result = entry.raw(params, session);
        if (notification) return std::nullopt;
        return R"({"id":)" + text_of(id) + R"(,"jsonrpc":"2.0","result":)" + result + "}";
      }
      json result = entry.handler(params, session);
      if (session.defer_token != 0) {
        if (!notification) session.open_requests.emplace_back(session.defer_token, id);
        session.defer_token = 0;
        return std::nullopt;
      }
      if (notification) return std::nullopt;
      return text_of(json{{"jsonrpc", "2.0"}, {"id", id}, {"result", std::move(result)}});
    } catch (const RpcError& e) {
      refused = e.what();
      return reply_error(e.code(), e.what());
    } catch (const TaskError& e) {
      refused = e.what();
      return reply_error(rpc_code(e.kind()), e.what());
    } catch (const std::exception& e) {
      // The params were checked against the table: what is left is a fault of cncd's own, to
      // be found in the log rather than in a library's words to the client.
      spdlog::error("{}: {}", name, e.what());
      refused = "internal error";
      return reply_error(kInternalError,
                         "internal error in " + quoted_text(name) + "; see cncd's log");
    }
  }();
  if (on_behalf && after.events != nullptr && entry.spec.recorded) {
    // What a person did through a front end, as the front end vouches: the audit trail.
    std::string what = name;
    if (!params.empty()) {
      std::string shown = text_of(params);
      if (shown.size() > kRecordedParamsBytes)
        shown = shown.substr(0, kRecordedParamsBytes) + "...";
      what += " " + shown;
    }
    what += " by " + actor;
    if (!refused.empty()) what += ": refused: " + refused;
    after.events->add("info", "command", std::move(what));
  }
  return outcome;
}

namespace {

// Notes for each request of a line (by its index in a batch; 0 alone) the first key it repeats
// in any of its objects: nlohmann::json keeps the last value silently. A SAX pass of its own,
// as the parser's callback interface takes quadratic time over a batch of many objects.
class RepeatFinder : public json::json_sax_t {
 public:
  std::map<std::size_t, RpcDispatcher::RepeatedKey> repeats;

  bool null() override { return value(); }
  bool boolean(bool) override { return value(); }
  bool number_integer(number_integer_t) override { return value(); }
  bool number_unsigned(number_unsigned_t) override { return value(); }
  bool number_float(number_float_t, const string_t&) override { return value(); }
  bool string(string_t&) override { return value(); }
  bool binary(binary_t&) override { return value(); }
  bool start_object(std::size_t) override {
    value();
    open_.emplace_back(std::set<std::string>());
    return true;
  }
  bool key(string_t& key) override {
    if (open_.empty() || !open_.back() || open_.back()->insert(key).second) return true;
    auto& repeat = repeats[batch_ ? requests_ - 1 : 0];
    if (repeat.key.empty()) repeat.key = key;
    // The request's own keys: those of the top-level object or of a batch's element.
    if (key == "id" && open_.size() == (batch_ ? 2u : 1u)) repeat.id = true;
    return true;
  }
  bool end_object() override { return end(); }
  bool start_array(std::size_t) override {
    value();
    if (open_.empty()) batch_ = true;
    open_.emplace_back(std::nullopt);
    return true;
  }
  bool end_array() override { return end(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  // A value begins: in a batch, at its top level, that is the next request.
  bool value() {
    if (batch_ && open_.size() == 1) ++requests_;
    return true;
  }
  bool end() {
    if (!open_.empty()) open_.pop_back();
    return true;
  }
  std::vector<std::optional<std::set<std::string>>> open_;  // keys of each open object
  bool batch_ = false;
  std::size_t requests_ = 0;
};

}  // namespace

RpcDispatcher::Line RpcDispatcher::begin_line(const std::string& text) const {
  Line line;
  if (nested_too_deep(text)) {
    line.whole =
        error_response(nullptr, kInvalidRequest,
                       "request nested deeper than " + std::to_string(kMaxNesting) + " levels")
            .dump();
    return line;
  }
  json request = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (request.is_discarded()) {
    line.whole = error_response(nullptr, kParseError, "parse error: not valid JSON").dump();
    return line;
  }
  if (request.is_array()) {
    if (request.empty()) {
      line.whole = error_response(nullptr, kInvalidRequest, "empty batch").dump();
      return line;
    }
    if (request.size() > kMaxBatch) {
      line.whole =
          error_response(nullptr, kInvalidRequest,
                         "a batch may hold at most " + std::to_string(kMaxBatch) + " requests")
              .dump();
      return line;
    }
  }
  RepeatFinder finder;
  json::sax_parse(text, &finder);
  line.repeats = std::move(finder.repeats);
  line.batch = request.is_array();
  if (line.batch) {
    line.requests = std::move(request);
  } else {
    line.requests.push_back(std::move(request));
  }
  return line;
}

bool RpcDispatcher::serve(Line& line, Session& session, std::size_t& budget) const {
  if (line.whole) return true;
  session.in_batch = line.batch;
  bool first = true;
  while (line.next < line.requests.size() && (first || budget > 0)) {
    first = false;
    const std::size_t i = line.next++;
    const auto repeat = line.repeats.find(i);
    auto response = handle_one(line.requests[i], session,
                               repeat == line.repeats.end() ? nullptr : &repeat->second);
    line.requests[i] = nullptr;  // served: its memory is not held until the batch ends
    std::size_t cost = kRequestCost;
    if (response) {
      if (line.answered++ > 0) line.answers += ',';
      line.answers += *response;
      cost += response->size();
    }
    budget -= std::min(budget, cost);
  }
  session.in_batch = false;
  return line.next >= line.requests.size();
}

std::optional<std::string> RpcDispatcher::answer(Line& line) {
  if (line.whole) return std::move(*line.whole);
  if (line.answered == 0) return std::nullopt;
  if (line.batch) return "[" + line.answers + "]";
  return std::move(line.answers);
}

std::optional<std::string> RpcDispatcher::handle_line(const std::string& text, Session& session,
                                                      std::size_t* requests) const {
  Line line = begin_line(text);
  if (requests != nullptr) *requests = line.batch ? line.requests.size() : 1;
  std::size_t unlimited = SIZE_MAX;
  serve(line, session, unlimited);
  return answer(line);
}

int rpc_code(TaskErrorKind kind) {
  // In TaskErrorKind's order.
  static constexpr int kCodes[] = {kWrongState, kNotHomed,      kProgramError,
                                   kBusy,       kInvalidParams, kFileError,
                                   kFault,      kCancelled,     kUnavailable};
  static_assert(std::size(kCodes) == static_cast<std::size_t>(TaskErrorKind::unavailable) + 1);
  const auto index = static_cast<std::size_t>(kind);
  return index < std::size(kCodes) ? kCodes[index] : kInternalError;
}

void Completions::post(std::uint64_t token, TaskOutcome outcome) {
  Completion done;
  done.token = token;
  if (const auto* error = std::get_if<TaskError>(&outcome)) {
    done.error_code = rpc_code(error->kind());
    done.error_message = error->what();
  } else if (const auto* opened = std::get_if<ProgramOpened>(&outcome)) {
    done.result = json{{"path", opened->path}};
  } else if (auto* preview = std::get_if<RawResult>(&outcome)) {
    done.raw_result = std::move(preview->json);
  } else {
    done.result = json{{"ok", true}};
  }
  done_.push_back(std::move(done));
}

}  // namespace cncd::daemon
