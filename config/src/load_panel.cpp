// [PANEL]: the machine's buttons, switches, MPG, override knobs and lights (docs/drivers.md,
// "Panel"). What each address can carry, and addresses shared with other keys, are checked
// with the other signals in validate_io.
#include <cmath>
#include <string>
#include <vector>

#include "loader.hpp"
#include "text.hpp"

namespace cncd::config {
namespace {

constexpr std::string_view kPanel = "PANEL";

// The key prefix of a counter: "MPG", "FEED_OVERRIDE" ...
std::string counter_prefix(int counter) {
  static constexpr std::string_view kNames[] = {"MPG", "FEED_OVERRIDE", "RAPID_OVERRIDE",
                                                "SPINDLE_OVERRIDE"};
  static_assert(std::size(kNames) == kPanelCounters);
  return std::string(kNames[counter]);
}

// JOG_<L>_PLUS, JOG_<L>_MINUS, MPG_AXIS_<L>: the letter, or '\0' for another key.
char axis_letter_of(std::string_view key) {
  if (key.starts_with("MPG_AXIS_") && key.size() == 10) return key[9];
  if (key.starts_with("JOG_") && key.size() >= 10 && key[5] == '_' &&
      (key.substr(6) == "PLUS" || key.substr(6) == "MINUS")) {
    return key[4];
  }
  return '\0';
}

// Keys of [PANEL] the table does not know; an axis key names the axes there are.
void check_unknown_keys(TypedReader& r, const MachineConfig& c) {
  for (const auto& entry : r.ini().entries()) {
    if (entry.section != kPanel || entry.section_occurrence != 0) continue;
    const char letter = axis_letter_of(entry.key);
    const bool axis_key = letter != '\0';
    if (!axis_key && find_key_spec(kPanel, entry.key) != nullptr) continue;
    if (axis_key && c.coordinates.find(letter) != std::string::npos) continue;
    if (axis_key) {
      r.entry(kPanel, entry.key);  // reported here
      r.problem(kPanel, entry.key,
                "the machine has no axis " + std::string(1, letter) + " ([TRAJ] COORDINATES = " +
                    c.coordinates + "): jog buttons and MPG axis switches are for its axes");
      continue;
    }
    r.problem(kPanel, entry.key,
              "unknown key in the panel's section" + did_you_mean(kPanel, entry.key));
  }
}

// Settings of an MPG or knob that is not wired: read by nobody, which the integrator should know.
void warn_unwired(TypedReader& r, bool wired, const std::vector<std::string>& wiring,
                  const std::vector<std::string>& settings, const std::string& what) {
  if (wired) return;
  for (const std::string& key : wiring) {
    if (r.failed(kPanel, key)) return;  // its own problem says enough
  }
  for (const std::string& key : settings) {
    if (r.given(kPanel, key)) r.warning(kPanel, key, "ignored: " + what);
  }
}

void load_counter(TypedReader& r, const std::string& prefix, PanelCounterWiring& w) {
  w.a = r.signal(kPanel, prefix + "_A");
  w.b = r.signal(kPanel, prefix + "_B");
  w.counts = r.signal(kPanel, prefix + "_COUNTS");
  const bool a = w.a.given() || r.failed(kPanel, prefix + "_A");
  const bool b = w.b.given() || r.failed(kPanel, prefix + "_B");
  if (a != b) {
    const std::string given = prefix + (a ? "_A" : "_B");
    r.problem(
        kPanel, given,
        given + " needs " + prefix + (a ? "_B" : "_A") + ": an encoder has two channels, A and B");
  }
  if ((a || b) && w.counts.given()) {
    r.problem(kPanel, prefix + "_COUNTS",
              "give the count once: " + prefix + "_A/" + prefix + "_B (an encoder) or " + prefix +
                  "_COUNTS (a counter), not both");
  }
}

void load_knob(TypedReader& r, const std::string& prefix, OverrideKnob& k) {
  load_counter(r, prefix, k.encoder);
  if (const auto v = r.real(kPanel, prefix + "_SCALE")) k.per_count = *v;
  k.analog = r.signal(kPanel, prefix + "_ANALOG");
  if (const auto v = r.real(kPanel, prefix + "_ANALOG_MIN")) k.analog_min = *v;
  if (const auto v = r.real(kPanel, prefix + "_ANALOG_MAX")) k.analog_max = *v;
  if (k.analog.given() && k.encoder.given()) {
    r.problem(kPanel, prefix + "_ANALOG",
              "a knob is an encoder or an analog input, not both: " + prefix +
                  (k.encoder.counts.given() ? "_COUNTS" : "_A") + " is given too");
  }
  const std::string min_key = prefix + "_ANALOG_MIN";
  const std::string max_key = prefix + "_ANALOG_MAX";
  const std::vector<std::string> encoder = {prefix + "_A", prefix + "_B", prefix + "_COUNTS"};
  warn_unwired(r, k.encoder.given(), encoder, {prefix + "_SCALE"},
               "no encoder (" + prefix + "_A and _B, or " + prefix + "_COUNTS)");
  warn_unwired(r, k.analog.given(), {prefix + "_ANALOG"}, {min_key, max_key},
               "no analog input (" + prefix + "_ANALOG)");
  if (!(k.analog_min < k.analog_max) && !r.failed(kPanel, min_key) && !r.failed(kPanel, max_key)) {
    r.problem(kPanel, r.given(kPanel, max_key) ? max_key : min_key,
              max_key + " " + format_number(k.analog_max) + " must be above " + min_key + " " +
                  format_number(k.analog_min));
  }
}

void load_mpg(TypedReader& r, const MachineConfig& c, PanelConfig& p) {
  load_counter(r, "MPG", p.mpg);
  if (const auto v = r.integer(kPanel, "MPG_COUNTS_PER_DETENT")) {
    p.mpg_counts_per_detent = static_cast<int>(*v);
  }
  if (c.linear_units == LinearUnits::inch) p.mpg_step_distance = {0.0001, 0.001, 0.01};
  static constexpr const char* kSteps[] = {"MPG_STEP_1_DISTANCE", "MPG_STEP_10_DISTANCE",
                                           "MPG_STEP_100_DISTANCE"};
  for (std::size_t i = 0; i < p.mpg_step_distance.size(); ++i) {
    if (const auto v = r.real(kPanel, kSteps[i])) p.mpg_step_distance[i] = *v;
  }
  if (const auto v = r.choice(kPanel, "MPG_MODE")) {
    p.mpg_mode = *v == "velocity" ? PanelConfig::MpgMode::velocity : PanelConfig::MpgMode::position;
  }
  if (const auto v = r.choice(kPanel, "MPG_OVERRIDE")) p.mpg_override_feed = *v == "feed";
  warn_unwired(
      r, p.mpg.given(), {"MPG_A", "MPG_B", "MPG_COUNTS"},
      {"MPG_COUNTS_PER_DETENT", kSteps[0], kSteps[1], kSteps[2], "MPG_MODE", "MPG_OVERRIDE"},
      "no MPG (MPG_A and MPG_B, or MPG_COUNTS)");
}

}  // namespace

std::vector<PanelSignal> panel_signals(const PanelConfig& p) {
  std::vector<PanelSignal> out;
  const auto add = [&](std::string key, const SignalAddress& a, SignalUse use) {
    if (a.given()) out.push_back(PanelSignal{std::move(key), &a, use});
  };
  for (int i = 0; i < kPanelInputs; ++i) {
    add(panel_input_key(static_cast<PanelInput>(i)), p.inputs[static_cast<std::size_t>(i)],
        SignalUse::panel_button);
  }
  for (int n = 0; n < kPanelCounters; ++n) {
    const PanelCounterWiring& w = n == 0 ? p.mpg : p.knobs[static_cast<std::size_t>(n - 1)].encoder;
    const std::string prefix = counter_prefix(n);
    add(prefix + "_A", w.a, SignalUse::panel_encoder);
    add(prefix + "_B", w.b, SignalUse::panel_encoder);
    add(prefix + "_COUNTS", w.counts, SignalUse::panel_counter);
  }
  for (int k = 0; k < kPanelAnalogs; ++k) {
    add(counter_prefix(k + 1) + "_ANALOG", p.knobs[static_cast<std::size_t>(k)].analog,
        SignalUse::panel_analog);
  }
  for (int l = 0; l < kPanelLights; ++l) {
    add(std::string(panel_light_key(static_cast<PanelLight>(l))),
        p.lights[static_cast<std::size_t>(l)], SignalUse::digital_output);
  }
  return out;
}

void load_panel(TypedReader& r, MachineConfig& c) {
  PanelConfig& p = c.panel;
  p.present = r.ini().has_section(kPanel);
  if (!p.present) return;
  check_unknown_keys(r, c);
  if (const auto v = r.integer(kPanel, "DEBOUNCE_MS")) p.debounce_ms = static_cast<int>(*v);
  if (const auto v = r.choice(kPanel, "DOOR_MODE")) {
    p.door_mode = *v == "estop" ? PanelConfig::DoorMode::estop : PanelConfig::DoorMode::hold;
  }
  for (int i = 0; i < kPanelInputs; ++i) {
    const std::string key = panel_input_key(static_cast<PanelInput>(i));
    const char letter = axis_letter_of(key);
    // A key of an axis the machine lacks was refused by check_unknown_keys.
    if (letter != '\0' && c.coordinates.find(letter) == std::string::npos) continue;
    p.inputs[static_cast<std::size_t>(i)] = r.signal(kPanel, key);
  }
  load_mpg(r, c, p);
  for (int k = 0; k < kPanelAnalogs; ++k) {
    load_knob(r, counter_prefix(k + 1), p.knobs[static_cast<std::size_t>(k)]);
  }
  for (int l = 0; l < kPanelLights; ++l) {
    p.lights[static_cast<std::size_t>(l)] =
        r.signal(kPanel, panel_light_key(static_cast<PanelLight>(l)));
  }
}

}  // namespace cncd::config
