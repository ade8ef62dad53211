// Every method and its parameters, in one place: the dispatcher refuses to register a method
// that is not here and checks each request against its entry before the handler runs.
// docs/protocol.md's parameter table lists the same (tests/daemon/rpc_params_test.cpp checks).
// Ranges that depend on the machine's configuration are narrowed when the handler is
// registered; the handlers check what depends on state (a program's length, an axis letter).
#include "rpc_params.hpp"

namespace cncd::daemon {

namespace {

using enum ParamType;

// A bitmask of joints holds 32.
constexpr double kMaxJoint = 31;
constexpr double kMaxTool = 99999;

constexpr ParamSpec kFields{
    .name = "fields", .type = string_list, .note = "top-level status fields; all if empty"};
constexpr ParamSpec kAxis{
    .name = "axis", .type = string, .note = "an axis letter such as \"X\"; or \"joint\" instead"};
constexpr ParamSpec kJoint{.name = "joint",
                           .type = integer,
                           .min = 0,
                           .max = kMaxJoint,
                           .note = "a joint number: jogs that joint alone (joint mode)"};

constexpr ParamSpec required(std::string_view name, ParamType type, std::string_view note) {
  return {.name = name, .type = type, .required = true, .note = note};
}

// A number of `type` from `min` to `max`.
constexpr ParamSpec bounded(std::string_view name, ParamType type, double min, double max,
                            std::string_view note, bool required = false) {
  return {.name = name, .type = type, .required = required, .min = min, .max = max, .note = note};
}

// The one parameter of the override methods: a ratio, at most `max`.
constexpr ParamSpec override_ratio(std::string_view note, double max = kUnbounded) {
  return {.name = "value", .type = number, .required = true, .min = 0, .max = max, .note = note};
}

}  // namespace

const std::vector<MethodSpec>& method_table() {
  static const std::vector<MethodSpec> table = {
      {"status.get", Access::read, {kFields}},
      {"status.subscribe",
       Access::read,
       {bounded("interval_ms", integer, 10, 3'600'000, "milliseconds between updates, default 100"),
        kFields}},
      {"status.unsubscribe", Access::read, {}},
      {"errors.list",
       Access::read,
       {{.name = "since", .type = integer, .min = 0, .note = "the last event seq already seen"}}},
      {"system.info", Access::read, {}},
      {"jobs.history",
       Access::read,
       {bounded("since", number, 0, kUnbounded,
                "Unix time: runs started at or after it, default 0"),
        bounded("limit", integer, 1, 1000, "the newest runs to answer with, default 100")}},
      {"jobs.stats",
       Access::read,
       {bounded("since", number, 0, kUnbounded,
                "Unix time: runs started at or after it, default 0")}},
      {"machine.estop", Access::control, {}},
      {"machine.reset", Access::control, {}},
      {"machine.on", Access::control, {}},
      {"machine.off", Access::control, {}},
      {"machine.home",
       Access::control,
       {bounded("joints", integer_list, 0, kMaxJoint, "joint numbers")}},
      {"jog.start",
       Access::control,
       {kAxis, kJoint, required("velocity", number, "machine units per second, signed, not 0"),
        bounded("heartbeat_s", number, 0.05, 5,
                "seconds: the jog stops when no jog.heartbeat came for that long")}},
      {"jog.stop", Access::control, {kAxis, kJoint}},
      {"jog.heartbeat",
       Access::control,
       {{.name = "axis",
         .type = string,
         .note = "an axis letter; all of this connection's jogs if left out"},
        kJoint},
       /*recorded=*/false},
      {"jog.increment",
       Access::control,
       {kAxis,
        kJoint,
        required("distance", number, "machine units, signed, not 0"),
        {.name = "velocity", .type = number, .note = "machine units per second, above 0"}}},
      {"program.open", Access::control, {required("path", string, "the program file")}},
      {"program.preview",
       Access::read,
       {bounded("tolerance", number, 1e-6, 1000,
                "machine units the drawing may pass from the path; default 0.01 mm, 0.0004 in")}},
      {"program.run",
       Access::control,
       {bounded("from_line", integer, 1, 100'000'000, "the program line to run from")}},
      {"program.step", Access::control, {}},
      {"program.pause", Access::control, {}},
      {"program.resume", Access::control, {}},
      {"program.abort", Access::control, {}},
      {"mdi.execute", Access::control, {required("line", string, "one block of G code")}},
      {"override.feed", Access::control, {override_ratio("feed override ratio, 1.0 = 100 %")}},
      {"override.rapid", Access::control, {override_ratio("rapid override ratio, 1.0 = 100 %", 1)}},
      {"override.spindle",
       Access::control,
       {override_ratio("spindle override ratio, 1.0 = 100 %")}},
      {"tool.list", Access::read, {}},
      {"tool.change_done",
       Access::control,
       {bounded("tool", integer, 0, kMaxTool, "the tool the change waits for", true)}},
      {"wait.done",
       Access::control,
       {required("kind", string, "\"input\" (M66) or \"spindle_at_speed\"")}},
      {"tool.set",
       Access::control,
       {bounded("number", integer, 1, kMaxTool, "tool number", true),
        bounded("pocket", integer, 1, kMaxTool, "pocket number"),
        {.name = "offset", .type = axis_values, .note = "tool offset, machine units"},
        bounded("diameter", number, 0, 1e6, "machine units"),
        bounded("front_angle", number, -360, 360, "degrees"),
        bounded("back_angle", number, -360, 360, "degrees"),
        bounded("orientation", integer, 0, 9, "lathe tool orientation"),
        {.name = "comment", .type = string, .note = "one line of at most 200 characters"}}},
      {"sim.set",
       Access::control,
       {required("signal", string, "the NAME of a sim:NAME input the machine's INI names"),
        required("value", number,
                 "0 or 1 (a digital input), an integer (a counter), a number (an analog input)")}},
      {"offsets.get", Access::read, {}},
      {"offsets.set",
       Access::control,
       {required("system", coord_system, "the one to set"),
        {.name = "origin", .type = axis_values, .note = "machine units"},
        bounded("rotation", number, -360, 360, "degrees about Z")}},
  };
  return table;
}

}  // namespace cncd::daemon
