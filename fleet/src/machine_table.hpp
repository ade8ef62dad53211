// The machines seen on the broker, one row each, built from their retained state, their
// availability and their events. Everything that comes in is bounded and checked: a payload
// over the size limit, JSON that does not parse, a field of the wrong type, a topic outside
// the pattern or a machine beyond the table's limit is counted, logged (at the first and then
// at each power of two of its kind) and otherwise ignored; text is cut to a bounded length;
// a dashboard link is kept only when it is http:// or https://.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace cncd::fleet {

struct TableLimits {
  std::size_t max_machines = 2000;
  std::size_t max_payload = 64 * 1024;
  std::size_t max_text = 512;  // characters kept of a name, program path or alarm text
};

// The topic filters a pattern such as "cncd/+" subscribes to ("cncd/+/state" ...); "" when
// the pattern is usable, else why not.
std::string check_pattern(const std::string& pattern);
std::vector<std::string> topic_filters(const std::string& pattern);

class MachineTable {
 public:
  enum class Outcome { changed, unchanged, ignored };
  // Why a message was ignored, for the counters and the log.
  enum class Refusal { too_large, bad_topic, bad_json, table_full, bad_value };

  MachineTable(std::string pattern, TableLimits limits);

  // One message as the broker delivered it.
  Outcome apply(std::string_view topic, std::string_view payload, double now);
  // A refusal seen before apply (the subscriber drops oversized payloads unread).
  void refuse(Refusal why, std::string_view topic, std::size_t bytes);

  // Every row, sorted by id.
  nlohmann::json rows() const;
  nlohmann::json row(const std::string& id) const;
  bool has(const std::string& id) const { return machines_.count(id) != 0; }
  // The ids changed (or removed: no longer has()) since the last call.
  std::vector<std::string> take_changed();
  std::size_t size() const { return machines_.size(); }
  std::uint64_t refused(Refusal why) const;
  std::uint64_t refused_total() const;

 private:
  struct Machine {
    nlohmann::json state;   // the row's state fields; null: no state
    nlohmann::json online;  // "online", "offline" or null
    nlohmann::json alarm;   // {seq, time, kind, message} or null
    double seen = 0;        // Unix time of the last message
  };
  // The machine id of a topic under the pattern and its last level; false when outside.
  bool split(std::string_view topic, std::string& id, std::string& kind) const;
  bool on_state(Machine& m, const nlohmann::json& payload);
  bool on_event(Machine& m, const nlohmann::json& payload);
  nlohmann::json text(const nlohmann::json& value) const;
  Outcome ignore(Refusal why, std::string_view topic, const std::string& detail);

  std::vector<std::string> pattern_;
  TableLimits limits_;
  std::map<std::string, Machine> machines_;
  std::set<std::string> changed_;
  std::map<Refusal, std::uint64_t> refused_;
};

}  // namespace cncd::fleet
