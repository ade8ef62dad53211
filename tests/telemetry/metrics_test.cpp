// Prometheus' /metrics from the real cncd-telemetry: read by Prometheus' own text-format parser
// (python3-prometheus-client), its counters against status.get and the job history.
#include <cmath>
#include <fstream>
#include <regex>

#include "telemetry_fixture.hpp"

namespace cncd::test {
namespace {

using nlohmann::json;

constexpr const char* kParse = R"(
import json, sys
from prometheus_client.parser import text_string_to_metric_families
out = {}
for family in text_string_to_metric_families(open(sys.argv[1]).read()):
    for s in family.samples:
        out.setdefault(s.name, []).append({"labels": s.labels, "value": s.value})
    out.setdefault("#types", {})[family.name] = family.type
print(json.dumps(out))
)";

// The samples by name, as Prometheus' parser reads `text`; fails the test when it cannot.
json parse(const TempDir& dir, const std::string& text) {
  const auto file = dir.write("metrics.txt", text);
  const auto r = run_command({CNCD_PYTHON3, "-c", kParse, file.string()});
  EXPECT_EQ(r.exit_status, 0) << r.err;
  return json::parse(r.out, nullptr, false);
}

double value_of(const json& samples, const std::string& name, const json& labels = json::object()) {
  for (const auto& s : samples.value(name, json::array())) {
    bool match = true;
    for (const auto& [key, value] : labels.items())
      match = match && s["labels"].value(key, "") == value;
    if (match) return s["value"].get<double>();
  }
  ADD_FAILURE() << "no sample " << name << " " << labels.dump();
  return -1;
}

TEST_F(TelemetryTest, MetricsParseAndAgreeWithTheStatusAndTheJobHistory) {
  ready_machine();
  start_program("part.ngc", "G21 G90 F3000\nG1 X5 Y5\nM3 S1000\nG1 X10\nM5\nM30\n");
  wait_until([](const json& s) { return s["exec"] == "idle" && s["program"]["result"] != ""; });
  start_program("m2.ngc", "G21 G90 F3000\nG1 X1\nM2\n");
  wait_until([](const json& s) { return s["exec"] == "idle" && s["program"]["result"] != ""; });
  const std::string machine = "cncd_sim_mill__mm_";
  metrics_with("cncd_jobs_total{machine=\"" + machine + "\",result=\"done\"} 2");
  const json before = status();
  // cncd-telemetry's status is at most one update (100 ms) old: wait past that, so that what
  // /metrics shows was read after `before`.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const json samples = parse(dir_, metrics());
  const json after = status();
  ASSERT_TRUE(samples.is_object());
  // Counters and gauges as Prometheus reads them.
  EXPECT_EQ(samples["#types"]["cncd_servo_overruns"], "counter");
  EXPECT_EQ(samples["#types"]["cncd_jobs"], "counter");
  EXPECT_EQ(samples["#types"]["cncd_machine_state"], "gauge");
  // The overruns between two reads of the status.
  const double overruns = value_of(samples, "cncd_servo_overruns_total");
  EXPECT_GE(overruns, before["rt"]["overruns"].get<double>());
  EXPECT_LE(overruns, after["rt"]["overruns"].get<double>());
  const double cycles = value_of(samples, "cncd_servo_cycles_total");
  EXPECT_GE(cycles, before["rt"]["cycles"].get<double>());
  EXPECT_LE(cycles, after["rt"]["cycles"].get<double>());
  // The jobs as the history has them.
  const json stats = result_of(call("jobs.stats"));
  EXPECT_EQ(value_of(samples, "cncd_jobs_total", {{"result", "done"}}),
            stats["by_result"]["done"].get<double>());
  EXPECT_EQ(value_of(samples, "cncd_parts_total"), 1);
  EXPECT_DOUBLE_EQ(value_of(samples, "cncd_job_cycle_seconds_total"),
                   stats["cycle_s"].get<double>());
  EXPECT_EQ(value_of(samples, "cncd_up"), 1);
  EXPECT_EQ(value_of(samples, "cncd_machine_state", {{"state", "on"}}), 1);
  EXPECT_EQ(value_of(samples, "cncd_joint_homed", {{"joint", "2"}}), 1);
  // Every metric the Grafana dashboard in docs/ plots is served.
  const std::string dashboard =
      slurp(std::string(CNCD_SOURCE_DIR) + "/docs/grafana-dashboard.json");
  ASSERT_FALSE(dashboard.empty());
  const std::regex metric("cncd_[a-z_]+");
  int plotted = 0;
  for (auto it = std::sregex_iterator(dashboard.begin(), dashboard.end(), metric);
       it != std::sregex_iterator(); ++it) {
    ++plotted;
    EXPECT_TRUE(samples.contains(it->str())) << it->str() << " is plotted but not served";
  }
  EXPECT_GE(plotted, 10);
  // The events it has seen: both programs started and finished.
  EXPECT_GE(value_of(samples, "cncd_events_total", {{"level", "info"}, {"kind", "program"}}), 4);
}

TEST_F(TelemetryTest, TheWakeUpHistogramBusErrorsAndClientsAgreeWithTheStatus) {
  // Two more clients: the count is this test's, cncd-telemetry's and these.
  daemon::Client second;
  daemon::Client third;
  ASSERT_EQ(second.connect(daemon_.socket()), "");
  ASSERT_EQ(third.connect(daemon_.socket()), "");
  // Counted once the daemon has taken them in.
  json before = status();
  for (int i = 0; i < 500 && before["clients"] != 4; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    before = status();
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const json samples = parse(dir_, metrics());
  const json after = status();
  ASSERT_TRUE(samples.is_object());
  EXPECT_EQ(before["clients"], 4);
  EXPECT_EQ(value_of(samples, "cncd_clients"), after["clients"].get<double>());
  // A histogram as Prometheus reads it: cumulative buckets in rising order, the last (+Inf)
  // the count, taken between the two reads of the status.
  EXPECT_EQ(samples["#types"]["cncd_servo_wake_latency_seconds"], "histogram");
  const json buckets = samples.value("cncd_servo_wake_latency_seconds_bucket", json::array());
  ASSERT_EQ(buckets.size(), before["rt"]["wake_error_below"].size() + 1);
  double edge = 0;
  double below = 0;
  for (const auto& bucket : buckets) {
    const std::string le = bucket["labels"]["le"];
    const double next = le == "+Inf" ? HUGE_VAL : std::stod(le);
    EXPECT_GT(next, edge) << le;
    EXPECT_GE(bucket["value"].get<double>(), below) << le;
    edge = next;
    below = bucket["value"].get<double>();
  }
  const double count = value_of(samples, "cncd_servo_wake_latency_seconds_count");
  EXPECT_EQ(buckets.back()["value"].get<double>(), count);
  EXPECT_GE(count, before["rt"]["wake_error_count"].get<double>());
  EXPECT_LE(count, after["rt"]["wake_error_count"].get<double>());
  EXPECT_GT(count, 0);
  EXPECT_GE(value_of(samples, "cncd_servo_wake_latency_seconds_sum"), 0);
  // The simulated machine has no field bus: none of its requests failed.
  EXPECT_EQ(after["rt"]["modbus_errors"], 0);
  EXPECT_EQ(value_of(samples, "cncd_modbus_exchange_errors_total"), 0);
}

TEST_F(TelemetryTest, CncdAwayIsUpZeroAndItsReturnIsSeen) {
  metrics_with("cncd_up{machine=\"cncd_sim_mill__mm_\"} 1");
  daemon_.stop();
  const std::string away = metrics_with("cncd_up{machine=\"cncd_sim_mill__mm_\"} 0");
  // No stale machine numbers while it is away.
  EXPECT_EQ(away.find("cncd_servo_cycles_total{"), std::string::npos) << away;
  ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string()}), "");
  metrics_with("cncd_up{machine=\"cncd_sim_mill__mm_\"} 1");
  metrics_with("cncd_machine_state{machine=\"cncd_sim_mill__mm_\",state=\"estop\"} 1");
}

TEST_F(TelemetryTest, OnlyGetMetricsIsServedAndAbuseCostsLittle) {
  EXPECT_EQ(get("/").status, 404);
  EXPECT_EQ(get("/metrics/../etc/passwd").status, 404);
  EXPECT_EQ(http_exchange(port_,
                          "POST /metrics HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\n"
                          "Connection: close\r\n\r\n")
                .status,
            405);
  // A header over 8 KiB and a body are refused by closing, not read on.
  EXPECT_EQ(
      http_exchange(port_, "GET /metrics HTTP/1.1\r\nX: " + std::string(20000, 'a') + "\r\n\r\n")
          .status,
      0);
  EXPECT_EQ(http_exchange(port_, "GARBAGE\r\n\r\n").status, 0);
  // Idle connections beyond the limit are closed at once; a scrape still gets through once
  // they go.
  std::vector<int> idle;
  for (int i = 0; i < 40; ++i) {
    const int fd = connect_loopback(port_);
    ASSERT_GE(fd, 0);
    idle.push_back(fd);
  }
  // The 33rd and later are closed at once; the first 32 wait for their request.
  EXPECT_TRUE(closed_by_peer(idle.back())) << "a 40th connection is served";
  for (const int fd : idle)
    ::close(fd);
  // Once the server has seen them go (it reads their end of file), a scrape gets through.
  int status = 0;
  for (int i = 0; i < 200 && status != 200; ++i) {
    status = get("/metrics").status;
    if (status != 200) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(status, 200);
}

}  // namespace
}  // namespace cncd::test
