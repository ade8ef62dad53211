#include "metrics.hpp"

#include "json_read.hpp"

#include <charconv>
#include <cmath>
#include <tuple>

namespace cncd::telemetry {

using nlohmann::json;

namespace {

// A label value with \, " and newline escaped as the format asks.
std::string escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

std::string number(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  // The shortest text that reads back as the same double.
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

class Writer {
 public:
  explicit Writer(std::string machine) : machine_(std::move(machine)) {}
  // A metric's HELP and TYPE lines, once before its samples.
  void family(const char* name, const char* type, const char* help) {
    out_ += std::string("# HELP ") + name + " " + help + "\n# TYPE " + name + " " + type + "\n";
  }
  // One sample; `labels` is "" or `key="value",...` already escaped.
  void sample(const char* name, double value, const std::string& labels = "") {
    out_ += std::string(name) + "{machine=\"" + escaped(machine_) + "\"" +
            (labels.empty() ? "" : "," + labels) + "} " + number(value) + "\n";
  }
  // A family with one sample.
  void single(const char* name, const char* type, const char* help, double value) {
    family(name, type, help);
    sample(name, value);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string machine_;
  std::string out_;
};

double num(const json& object, const char* key) {
  return number_at(object, key);
}

void state_metrics(Writer& w, const json& s) {
  w.family("cncd_machine_state", "gauge", "1 for the machine's state (estop, off, on)");
  for (const char* state : {"estop", "off", "on"}) {
    w.sample("cncd_machine_state", text_at(s, "state") == state ? 1 : 0,
             std::string("state=\"") + state + "\"");
  }
  w.family("cncd_program_exec", "gauge", "1 for the program's execution state");
  for (const char* exec : {"idle", "running", "paused"}) {
    w.sample("cncd_program_exec", text_at(s, "exec") == exec ? 1 : 0,
             std::string("exec=\"") + exec + "\"");
  }
  const json& program = object_at(s, "program");
  w.single("cncd_program_progress_ratio", "gauge", "The running program's progress, 0 to 1",
           num(program, "progress"));
  w.single("cncd_program_line", "gauge", "The program line being run", num(program, "line"));
}

void servo_metrics(Writer& w, const json& s, double period_s) {
  const json& rt = object_at(s, "rt");
  w.single("cncd_servo_cycles_total", "counter", "Servo thread cycles since cncd started",
           num(rt, "cycles"));
  w.single("cncd_servo_uptime_seconds_total", "counter",
           "Time the servo thread has run: cycles times the servo period",
           num(rt, "cycles") * period_s);
  w.single("cncd_servo_overruns_total", "counter",
           "Servo cycles that woke later than a whole period", num(rt, "overruns"));
  w.family("cncd_servo_wake_error_seconds", "gauge",
           "How late the servo thread wakes: quantiles over the recent cycles");
  for (const auto& [quantile, key] : {std::pair{"0.5", "wake_error_p50_ns"},
                                      {"0.99", "wake_error_p99_ns"},
                                      {"0.999", "wake_error_p999_ns"},
                                      {"1", "wake_error_max_ns"}}) {
    w.sample("cncd_servo_wake_error_seconds", num(rt, key) * 1e-9,
             std::string("quantile=\"") + quantile + "\"");
  }
  // The wake-up error as a histogram: cumulative buckets that aggregate across machines and
  // over time, which quantiles do not.
  w.family("cncd_servo_wake_latency_seconds", "histogram",
           "How late the servo thread wakes, since cncd started");
  for (const auto& bucket : array_at(rt, "wake_error_below")) {
    w.sample("cncd_servo_wake_latency_seconds_bucket", num(bucket, "count"),
             "le=\"" + number(num(bucket, "us") * 1e-6) + "\"");
  }
  w.sample("cncd_servo_wake_latency_seconds_bucket", num(rt, "wake_error_count"), "le=\"+Inf\"");
  w.sample("cncd_servo_wake_latency_seconds_sum", num(rt, "wake_error_sum_ns") * 1e-9);
  w.sample("cncd_servo_wake_latency_seconds_count", num(rt, "wake_error_count"));
  w.single("cncd_modbus_exchange_errors_total", "counter",
           "Modbus requests and connects that failed since cncd started", num(rt, "modbus_errors"));
}

void joint_metrics(Writer& w, const json& s) {
  const json& joints = array_at(s, "joints");
  for (const auto& [name, key, help] :
       {std::tuple{"cncd_joint_homed", "homed", "1 when the joint is homed"},
        {"cncd_joint_fault", "fault", "1 when the joint has a following error or limit fault"},
        {"cncd_joint_drive_fault", "drive_fault", "1 when the joint's drive reports a fault"},
        {"cncd_joint_stale", "stale", "1 when the joint's feedback has stopped coming"}}) {
    w.family(name, "gauge", help);
    for (std::size_t j = 0; j < joints.size(); ++j) {
      w.sample(name, flag_at(joints[j], key) ? 1 : 0,
               "joint=\"" + std::to_string(j) + "\",driver=\"" +
                   escaped(text_at(joints[j], "driver")) + "\"");
    }
  }
}

void motion_metrics(Writer& w, const json& s, const MachineFeed& feed) {
  const json& spindle = object_at(s, "spindle");
  const json& overrides = object_at(s, "overrides");
  w.single("cncd_spindle_speed_rpm", "gauge", "The spindle's measured speed",
           num(spindle, "actual_rpm"));
  w.single("cncd_spindle_run_seconds_total", "counter",
           "Time the spindle turned while cncd-telemetry watched", feed.spindle_run_s());
  w.single("cncd_path_velocity", "gauge", "The tool's path velocity, machine units per second",
           num(s, "velocity"));
  w.family("cncd_override_ratio", "gauge", "The overrides in force, 1 = as programmed");
  for (const char* kind : {"feed", "rapid", "spindle"})
    w.sample("cncd_override_ratio", num(overrides, kind), std::string("kind=\"") + kind + "\"");
  w.single("cncd_tool_number", "gauge", "The tool in the spindle",
           num(object_at(s, "tool"), "number"));
  w.single("cncd_clients", "gauge", "Connections to cncd's control socket, this one included",
           num(s, "clients"));
}

void job_metrics(Writer& w, const MachineFeed& feed) {
  const json& jobs = feed.jobs();
  if (!jobs.contains("jobs")) return;  // the history cannot be read: no numbers, not zeros
  w.family("cncd_jobs_total", "counter", "Program runs in the job history, by result");
  for (const auto& [result, count] : object_at(jobs, "by_result").items()) {
    if (count.is_number())
      w.sample("cncd_jobs_total", count.get<double>(), "result=\"" + escaped(result) + "\"");
  }
  w.single("cncd_parts_total", "counter", "Parts made ([TELEMETRY] PART_COUNT)",
           num(jobs, "parts"));
  w.single("cncd_job_cycle_seconds_total", "counter",
           "Summed cycle time of the runs in the job history", num(jobs, "cycle_s"));
  const json& last = feed.last_job();
  if (number_at(last, "cycle_s", -1) >= 0) {
    w.single("cncd_last_job_cycle_seconds", "gauge", "The cycle time of the last run that ended",
             num(last, "cycle_s"));
  }
}

}  // namespace

std::string prometheus_text(const MachineFeed& feed, const Counters& counters,
                            const std::string& machine_id) {
  Writer w(machine_id);
  w.single("cncd_up", "gauge", "1 while cncd-telemetry is connected to cncd",
           feed.connected() ? 1 : 0);
  const json& s = feed.status();
  if (feed.connected() && s.contains("state")) {
    const double period_s = num(object_at(feed.info(), "machine"), "servo_period_ns") * 1e-9;
    state_metrics(w, s);
    servo_metrics(w, s, period_s);
    joint_metrics(w, s);
    motion_metrics(w, s, feed);
  }
  job_metrics(w, feed);
  w.family("cncd_events_total", "counter",
           "cncd's events (errors, warnings, notices) seen by cncd-telemetry, by level and kind");
  for (const auto& [key, count] : counters.events) {
    w.sample("cncd_events_total", static_cast<double>(count),
             "level=\"" + escaped(key.first) + "\",kind=\"" + escaped(key.second) + "\"");
  }
  w.family("cncd_faults_total", "counter",
           "Faults that stopped the machine, by the servo thread's code (following_error, "
           "drive_fault, feedback_stale, min_limit_switch ...)");
  for (const auto& [code, count] : counters.faults)
    w.sample("cncd_faults_total", static_cast<double>(count), "code=\"" + escaped(code) + "\"");
  if (counters.mqtt) {
    w.single("cncd_telemetry_mqtt_connected", "gauge", "1 while the MQTT broker is connected",
             counters.mqtt_connected ? 1 : 0);
    w.single("cncd_telemetry_mqtt_queued_messages", "gauge",
             "Events and jobs waiting for the broker's acknowledgement",
             static_cast<double>(counters.mqtt_queued));
    w.single("cncd_telemetry_mqtt_dropped_total", "counter",
             "Events and jobs dropped unsent: the queue ([TELEMETRY] EVENT_QUEUE) was full",
             static_cast<double>(counters.mqtt_dropped));
  }
  return w.take();
}

}  // namespace cncd::telemetry
