// A structure-aware mutator for rpc_fuzz.cpp. Byte-level mutations rarely turn a request that
// passes the parameter check into one that is well-formed JSON yet holds a value of another
// type, range or shape, which is where a handler could trip over what the table let through.
// So half the time one line of the input that parses as JSON gets one value replaced, removed or
// added (parameter names of the method table, values at the edges of the ranges, every JSON
// type); otherwise, and when no line parses, libFuzzer's own mutations apply (with its
// dictionary, rpc.dict). Deterministic for a given seed, as libFuzzer requires.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rpc_params.hpp"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

using nlohmann::json;
using Rng = std::mt19937;

std::size_t pick(Rng& rng, std::size_t n) {
  return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
}

std::string random_method(Rng& rng) {
  const auto& table = cncd::daemon::method_table();
  return std::string(table[pick(rng, table.size())].name);
}

std::string random_param(Rng& rng) {
  const auto& table = cncd::daemon::method_table();
  for (int tries = 0; tries < 8; ++tries) {
    const auto& params = table[pick(rng, table.size())].params;
    if (!params.empty()) return std::string(params[pick(rng, params.size())].name);
  }
  return "fields";
}

json random_value(Rng& rng, int depth = 0) {
  switch (pick(rng, depth < 2 ? 12 : 9)) {
    case 0: {
      static const json kSmall[] = {nullptr, true, false, 0, -1, 1, 2, 3, 9, 10, 31, 32};
      return kSmall[pick(rng, std::size(kSmall))];
    }
    case 1: {
      static const json kEdges[] = {std::numeric_limits<std::int64_t>::max(),
                                    std::numeric_limits<std::int64_t>::min(),
                                    std::numeric_limits<std::uint64_t>::max(),
                                    std::int64_t{1} << 31,
                                    99999,
                                    100000,
                                    100'000'000,
                                    3'600'000};
      return kEdges[pick(rng, std::size(kEdges))];
    }
    case 2: {
      static const json kFloats[] = {1.5, 2.0, -0.0, 0.5, -360.0, 360.5, 1e-300, 1e308, -1e308};
      return kFloats[pick(rng, std::size(kFloats))];
    }
    case 3:
      return std::uniform_real_distribution<double>(-1000, 1000)(rng);
    case 4: {
      static const char* kStrings[] = {"",
                                       "X",
                                       "x",
                                       "Q",
                                       "XY",
                                       "G54",
                                       "g59.3",
                                       "G59.4",
                                       "state",
                                       "2.0",
                                       "a\nb",
                                       "\xc3\xa9",
                                       "M2",
                                       "G0 X1",
                                       "@PROGRAMS@/ok.ngc",
                                       "@PROGRAMS@/stops.ngc",
                                       "@PROGRAMS@/long.ngc",
                                       "/"};
      return kStrings[pick(rng, std::size(kStrings))];
    }
    case 5:
      return std::string(pick(rng, 2) == 0 ? 201 : 3000, 'x');
    case 6:
      return random_method(rng);
    case 7:
      return random_param(rng);
    case 8:
      return std::string(1, static_cast<char>('A' + pick(rng, 26)));
    case 9: {
      json list = json::array();
      for (std::size_t n = pick(rng, 4); n > 0; --n)
        list.push_back(random_value(rng, depth + 1));
      return list;
    }
    case 10: {
      json object = json::object();
      for (std::size_t n = pick(rng, 3); n > 0; --n)
        object[pick(rng, 2) == 0 ? random_param(rng) : std::string(1, "xyzaq"[pick(rng, 5)])] =
            random_value(rng, depth + 1);
      return object;
    }
    default: {
      json request = {{"jsonrpc", "2.0"}, {"id", pick(rng, 100)}, {"method", random_method(rng)}};
      if (pick(rng, 2) == 0)
        request["params"] = {{random_param(rng), random_value(rng, depth + 1)}};
      return request;
    }
  }
}

void collect(const json& value, const json::json_pointer& at,
             std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (value.is_object()) {
    for (const auto& [key, item] : value.items())
      collect(item, at / key, out);
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i)
      collect(value[i], at / i, out);
  }
}

// One change to one node of `line`.
void mutate_json(json& line, Rng& rng) {
  std::vector<json::json_pointer> nodes;
  collect(line, json::json_pointer(), nodes);
  const auto at = nodes[pick(rng, nodes.size())];
  json& node = line[at];
  switch (pick(rng, 5)) {
    case 0:  // remove it from its parent
      if (!at.empty()) {
        json& parent = line[at.parent_pointer()];
        if (parent.is_object()) {
          parent.erase(at.back());
        } else {
          parent.erase(static_cast<std::size_t>(std::stoul(at.back())));
        }
        return;
      }
      break;
    case 1:  // add a member or an item
      if (node.is_object()) {
        node[pick(rng, 3) == 0 ? std::string("params") : random_param(rng)] = random_value(rng);
        return;
      }
      if (node.is_array()) {
        node.insert(node.begin() + static_cast<std::ptrdiff_t>(pick(rng, node.size() + 1)),
                    random_value(rng));
        return;
      }
      break;
    case 2:  // a request made a batch, or a batch a request
      if (at.empty()) {
        json changed = line.is_array() && !line.empty() ? json(line[pick(rng, line.size())])
                                                        : json::array({line});
        line = std::move(changed);
        return;
      }
      break;
    default:
      break;
  }
  node = random_value(rng);
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size,
                                               std::size_t max_size, unsigned int seed) {
  Rng rng(seed);
  if (pick(rng, 2) == 0) return LLVMFuzzerMutate(data, size, max_size);
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string_view> lines;
  for (std::size_t start = 0; start < input.size();) {
    const auto end = input.find('\n', start);
    lines.push_back(input.substr(start, end == std::string_view::npos ? end : end - start + 1));
    start = end == std::string_view::npos ? input.size() : end + 1;
  }
  std::vector<std::size_t> parsed;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (json::accept(lines[i])) parsed.push_back(i);
  }
  if (parsed.empty()) return LLVMFuzzerMutate(data, size, max_size);
  const std::size_t chosen = parsed[pick(rng, parsed.size())];
  json line = json::parse(lines[chosen]);
  mutate_json(line, rng);
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i)
    out += i == chosen ? line.dump() + "\n" : std::string(lines[i]);
  if (out.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::memcpy(data, out.data(), out.size());
  return out.size();
}
