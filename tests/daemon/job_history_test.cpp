// The job history: the real daemon writes a row a program run to a real SQLite file in its
// state directory; jobs.history, jobs.stats and cncctl jobs read it back.
#include <sqlite3.h>
#include <sys/stat.h>

#include <fstream>
#include <thread>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Short moves, then M30: one part.
constexpr const char* kPart = "G21 G90 F3000\nG1 X5 Y5\nG1 X10\nG0 Z2\nM30\n";

class JobHistoryTest : public MachineTest {
 protected:
  json history(const json& params = json::object()) {
    return result_of(call("jobs.history", params))["jobs"];
  }
  json stats() { return result_of(call("jobs.stats", json::object())); }
  // Runs `text` to its end and returns the status then.
  json run_to_end(const std::string& name, const std::string& text) {
    start_program(name, text);
    return wait_until(
        [](const json& s) { return s["exec"] == "idle" && s["program"]["result"] != ""; });
  }
  // Waits until the history's newest run has `result`, and returns it.
  json newest_with(const std::string& result) {
    json newest;
    poll_status(
        [&] {
          return history({{"limit", 1}});
        },
        [&](const json& jobs) {
          if (jobs.empty()) return false;
          newest = jobs[0];
          return newest["result"] == result;
        },
        std::chrono::seconds(60));
    return newest;
  }
  void restart(const std::vector<std::string>& extra = {}) {
    daemon_.stop();
    std::vector<std::string> args{"--ini", ini_.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    ASSERT_EQ(daemon_.start(dir_.path(), args), "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }
  bool has_event(const std::string& kind, const std::string& text) {
    const json events = result_of(call("errors.list"))["events"];
    for (const auto& e : events) {
      if (e["kind"] == kind && e["message"].get<std::string>().find(text) != std::string::npos)
        return true;
    }
    ADD_FAILURE() << "no " << kind << " event with '" << text << "' in " << events.dump();
    return false;
  }
  fs::path database() const { return dir_.path() / "jobs.db"; }
};

std::string sha256sum(const fs::path& file) {
  const auto r = run_command({"/usr/bin/sha256sum", file.string()});
  return r.out.substr(0, 64);
}

TEST_F(JobHistoryTest, ARunIsOneRowWithItsResultCycleTimePartAndHash) {
  ready_machine();
  const json end = run_to_end("part.ngc", kPart);
  ASSERT_EQ(end["program"]["result"], "done") << end.dump();
  const json job = newest_with("done");
  EXPECT_EQ(job["program"], (dir_.path() / "part.ngc").string());
  EXPECT_EQ(job["sha256"], sha256sum(dir_.path() / "part.ngc"));
  EXPECT_EQ(job["parts"], 1);
  EXPECT_EQ(job["error"], "");
  EXPECT_EQ(job["from_line"], 0);
  // The cycle time is the run's, on the servo clock, as the status reports it.
  EXPECT_DOUBLE_EQ(job["cycle_s"].get<double>(), end["program"]["motion_s"].get<double>());
  EXPECT_GT(job["cycle_s"].get<double>(), 0.0);
  EXPECT_GE(job["ended"].get<double>(), job["started"].get<double>());
  EXPECT_NE(job["started_by"].get<std::string>().find("uid"), std::string::npos) << job.dump();

  // M2 counts no part by default ([TELEMETRY] PART_COUNT = m30).
  ASSERT_EQ(run_to_end("m2.ngc", "G21 G90 F3000\nG1 X3\nM2\n")["program"]["result"], "done");
  EXPECT_EQ(newest_with("done")["parts"], 0);
  const json s = stats();
  EXPECT_EQ(s["jobs"], 2);
  EXPECT_EQ(s["by_result"]["done"], 2);
  EXPECT_EQ(s["parts"], 1);
  const json jobs = history();
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_GT(jobs[0]["id"].get<int>(), jobs[1]["id"].get<int>()) << "newest first";
  EXPECT_DOUBLE_EQ(s["cycle_s"].get<double>(),
                   jobs[0]["cycle_s"].get<double>() + jobs[1]["cycle_s"].get<double>());
  // Runs started after a time only; the limit's bounds.
  EXPECT_TRUE(history({{"since", jobs[0]["started"].get<double>() + 1e6}}).empty());
  EXPECT_EQ(error_code(call("jobs.history", {{"limit", 0}})), -32602);

  // Kept across a restart; cncctl shows them.
  restart();
  EXPECT_EQ(history().size(), 2u);
  const auto listed = cncctl({"jobs"});
  EXPECT_EQ(listed.exit_status, 0) << listed.err;
  EXPECT_NE(listed.out.find("part.ngc"), std::string::npos) << listed.out;
  const auto totals = cncctl({"jobs", "stats"});
  EXPECT_NE(totals.out.find("parts       1"), std::string::npos)
      << totals.exit_status << totals.out << totals.err;
  EXPECT_EQ(cncctl({"jobs", "--limit", "0"}).exit_status, 64);
}

TEST_F(JobHistoryTest, AnAbortedRunAndARunFromALineSayWhatTheyWere) {
  ready_machine();
  start_program("long.ngc", "G21 G90 F100\nG1 X100\nF3000\nG1 Y10\nM30\n");
  newest_with("running");
  result_of(call("program.abort"));
  const json aborted = newest_with("aborted");
  EXPECT_EQ(aborted["parts"], 0);
  EXPECT_NE(aborted["error"].get<std::string>().find("abort"), std::string::npos);
  result_of(call("program.run", {{"from_line", 4}}));
  wait_until([](const json& s) { return s["exec"] == "idle"; });
  const json from_line = newest_with("done");
  EXPECT_EQ(from_line["from_line"], 4);
  EXPECT_TRUE(from_line["estimate_s"].is_null()) << "an estimate is of the whole program";
}

TEST_F(JobHistoryTest, PartCountM2CountsM2AndM30) {
  std::ofstream(ini_, std::ios::app) << "\n[TELEMETRY]\nPART_COUNT = m2\n";
  restart();
  ready_machine();
  ASSERT_EQ(run_to_end("m2.ngc", "G21 G90 F3000\nG1 X3\nM2\n")["program"]["result"], "done");
  EXPECT_EQ(newest_with("done")["parts"], 1);
  ASSERT_EQ(run_to_end("part.ngc", kPart)["program"]["result"], "done");
  EXPECT_EQ(newest_with("done")["parts"], 1);
  // A program that ends with '%' and no M2 makes no part.
  ASSERT_EQ(run_to_end("pct.ngc", "%\nG21 G90 F3000\nG1 X1\n%\n")["program"]["result"], "done");
  EXPECT_EQ(newest_with("done")["parts"], 0);
  EXPECT_EQ(stats()["parts"], 2);
}

TEST_F(JobHistoryTest, AKillMidRunLeavesAWholeDatabaseAndAnInterruptedRun) {
  ready_machine();
  start_program("long.ngc", "G21 G90 F100\nG1 X100\nG1 Y100\nM30\n");
  const json running = newest_with("running");
  daemon_.kill_hard();
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(database().c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* check = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &check, nullptr), SQLITE_OK);
    ASSERT_EQ(sqlite3_step(check), SQLITE_ROW);
    EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(check, 0)), "ok");
    sqlite3_finalize(check);
    sqlite3_close(db);
  }
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  ASSERT_EQ(client_.connect(daemon_.socket()), "");
  const json jobs = history();
  ASSERT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs[0]["id"], running["id"]);
  EXPECT_EQ(jobs[0]["result"], "interrupted");
  EXPECT_TRUE(jobs[0]["ended"].is_null());
  EXPECT_TRUE(has_event("jobs", "marked \"interrupted\""));
}

TEST_F(JobHistoryTest, AFifoWhereTheDatabaseShouldBeIsRefusedAndTheMachineRunsOn) {
  daemon_.stop();
  for (const char* suffix : {"", "-wal", "-shm"})
    fs::remove(database().string() + suffix);
  ASSERT_EQ(mkfifo(database().c_str(), 0600), 0);
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  ASSERT_EQ(client_.connect(daemon_.socket()), "");
  const json answer = call("jobs.history");
  EXPECT_EQ(error_code(answer), 1012) << answer.dump();
  const std::string message = answer["error"].value("message", "");
  EXPECT_NE(message.find(database().string()), std::string::npos) << message;
  EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
  ready_machine();
  EXPECT_EQ(run_to_end("part.ngc", kPart)["program"]["result"], "done");
  EXPECT_TRUE(has_event("jobs", "not a regular file"));
}

}  // namespace
}  // namespace cncd::test
