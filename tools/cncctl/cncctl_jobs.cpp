// cncctl jobs: the job history (jobs.history) and its totals (jobs.stats).
#include <cstdio>
#include <ctime>
#include <string>

#include "cncctl.hpp"

namespace cncd::cncctl {

using nlohmann::json;

namespace {

std::string local_time(double unix_seconds) {
  const auto when = static_cast<std::time_t>(unix_seconds);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", std::localtime(&when));
  return stamp;
}

// YYYY-MM-DD, local midnight, as Unix seconds.
double date_arg(const std::string& text) {
  std::tm day{};
  const char* end = strptime(text.c_str(), "%Y-%m-%d", &day);
  if (end == nullptr || *end != '\0') {
    throw UsageError{"--since needs a date as YYYY-MM-DD, not '" + printable(text) + "'"};
  }
  day.tm_isdst = -1;
  const std::time_t when = std::mktime(&day);
  if (when < 0) throw UsageError{"--since: '" + printable(text) + "' is before 1970"};
  return static_cast<double>(when);
}

std::string seconds_text(const json& value) {
  if (!value.is_number()) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f s", value.get<double>());
  return text;
}

void print_stats(const json& s) {
  std::string results;
  const json by_result = s.value("by_result", json::object());
  for (const auto& [name, count] : by_result.items())
    results += (results.empty() ? ": " : ", ") + printable(name) + " " + count.dump();
  std::printf("jobs        %s%s\n", s.value("jobs", json(0)).dump().c_str(), results.c_str());
  std::printf("parts       %s\n", s.value("parts", json(0)).dump().c_str());
  std::printf("cycle time  %s (runs that ended done: %s)\n",
              seconds_text(s.value("cycle_s", json())).c_str(),
              seconds_text(s.value("done_cycle_s", json())).c_str());
}

void print_jobs(const json& result) {
  std::printf("%6s  %-19s  %-11s  %10s  %5s  %s\n", "ID", "STARTED", "RESULT", "CYCLE", "PARTS",
              "PROGRAM");
  for (const auto& job : result.value("jobs", json::array())) {
    std::string program = text_field(job, "program");
    if (const int line = job.value("from_line", 0); line > 0)
      program += " (from line " + std::to_string(line) + ")";
    std::printf("%6lld  %-19s  %-11s  %10s  %5d  %s\n", job.value("id", 0LL),
                local_time(job.value("started", 0.0)).c_str(), text_field(job, "result").c_str(),
                seconds_text(job.value("cycle_s", json())).c_str(), job.value("parts", 0),
                program.c_str());
    if (const std::string error = text_field(job, "error"); !error.empty())
      std::printf("%40s%s\n", "", error.c_str());
  }
}

}  // namespace

int jobs(daemon::Client& client, const Args& args, bool json_output) {
  const std::string usage = "jobs [stats] [--since YYYY-MM-DD] [--limit N]";
  bool stats = false;
  json params = json::object();
  for (std::size_t i = 1; i < args.size(); ++i) {
    if (args[i] == "stats" && i == 1) {
      stats = true;
    } else if (args[i] == "--since" && i + 1 < args.size()) {
      params["since"] = date_arg(args[++i]);
    } else if (args[i] == "--limit" && i + 1 < args.size() && !stats) {
      const double limit = number_arg(args[++i], "--limit");
      if (limit < 1 || limit > 1000 || limit != static_cast<double>(static_cast<int>(limit)))
        throw UsageError{"--limit needs a whole number from 1 to 1000"};
      params["limit"] = static_cast<int>(limit);
    } else {
      throw UsageError{"usage: " + usage};
    }
  }
  const json result = result_of(client.call(stats ? "jobs.stats" : "jobs.history", params));
  if (json_output) {
    std::printf("%s\n", result.dump(2).c_str());
  } else if (stats) {
    print_stats(result);
  } else {
    print_jobs(result);
  }
  return kDone;
}

}  // namespace cncd::cncctl
