// The canonical machining commands the interpreter emits (NIST RS274NGC vocabulary, as
// LinuxCNC names them), one type per command with its arguments as named fields. Positions are
// in the program's current length units (the last UseLengthUnits) and in program coordinates,
// exactly what LinuxCNC's canon layer receives; to_machine.hpp turns them into machine moves.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace cncd::interp {

inline constexpr int kAxes = 9;  // X Y Z A B C U V W
using Pose = std::array<double, kAxes>;

// CANON_PLANE_XY/YZ/XZ, and G17.1/G19.1/G18.1's CANON_PLANE_UV/VW/UW.
enum class Plane : std::uint8_t { xy = 1, yz = 2, xz = 3, uv = 4, vw = 5, uw = 6 };
// The axis indices of a plane as LinuxCNC's ARC_FEED orders them: XY (0, 1, 2), XZ (2, 0, 1),
// YZ (1, 2, 0), UV (6, 7, 8), VW (7, 8, 6), UW (8, 6, 7). A canned cycle drills along the
// normal and places its holes on the other two.
struct PlaneAxes {
  std::size_t first;
  std::size_t second;
  std::size_t normal;
};
PlaneAxes plane_axes(Plane plane);
enum class Units : std::uint8_t { inches = 1, mm = 2, cm = 3 };
enum class MotionMode : std::uint8_t { exact_stop = 1, exact_path = 2, continuous = 3 };
// SET_FEED_MODE's mode: inverse time (G93) is per minute here, its rate set move by move.
enum class FeedRateMode : int { per_minute = 0, per_revolution = 1 };

struct StraightTraverse {
  Pose end{};
};
struct StraightFeed {
  Pose end{};
};
// ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point,
// a, b, c, u, v, w): "first" and "second" are the plane's axes (XY: X Y, YZ: Y Z, XZ: Z X;
// UV: U V, VW: V W, UW: W U),
// the axis point is on its normal; rotation > 0 counterclockwise, |rotation| turns.
struct ArcFeed {
  double first_end = 0;
  double second_end = 0;
  double first_axis = 0;  // the center
  double second_axis = 0;
  int rotation = 0;
  double axis_end_point = 0;
  Plane plane = Plane::xy;
  std::array<double, 6> abc_uvw{};  // end of A B C U V W

  // The end point and the center (the end with the center's two plane coordinates) as poses.
  Pose end() const;
  Pose center() const;
  void set_end(const Pose& end);
  void set_center(const Pose& center);
};
// G5 (cubic), G5.1 (quadratic) and G5.2 .. G5.3: a rational B-spline in the XY plane on the
// clamped uniform knot vector of its order (degree + 1); the first point is where the tool is,
// the curve ends on the last. G5 and G5.1 are Bezier curves: as many points as the order, all
// weights 1. Only X and Y of the points differ. rs274 prints NURBS_FEED(points, ...).
struct NurbsFeed {
  std::vector<Pose> points;
  std::vector<double> weights;
  int order = 4;
  // G93: the feed (length units per minute) that takes the curve in 1/F minutes; else 0.
  double inverse_time_feed = 0;
};
struct Dwell {
  double seconds = 0;
};
struct SetFeedRate {
  double rate = 0;  // length units per minute (per revolution under G95)
};
struct SetFeedMode {
  FeedRateMode mode = FeedRateMode::per_minute;
};
struct SetFeedReference {};  // always CANON_XYZ
struct SelectPlane {
  Plane plane = Plane::xy;
};
struct UseLengthUnits {
  Units units = Units::mm;
};
struct SetG5xOffset {
  int system = 1;  // 1..9 = G54..G59.3
  Pose offset{};
};
struct SetG92Offset {
  Pose offset{};
};
struct SetXyRotation {
  double degrees = 0;
};
struct UseToolLengthOffset {
  Pose offset{};
};
struct SetMotionControlMode {
  MotionMode mode = MotionMode::continuous;
  double tolerance = 0;  // G64 P
};
struct SetNaivecamTolerance {
  double tolerance = 0;  // G64 Q
};
struct StartSpindleClockwise {};
struct StartSpindleCounterclockwise {};
struct StopSpindleTurning {};
struct SetSpindleSpeed {
  double rpm = 0;
};
struct SetSpindleMode {
  double css_max_rpm = 0;  // 0: constant speed (G97)
};
struct MistOn {};
struct MistOff {};
struct FloodOn {};
struct FloodOff {};
struct SelectTool {  // T: the tool prepared
  int tool = 0;
};
// M6 and M61 name the tool by its number; `slot` is where it sits in the tool table (its line
// as loaded, from 1; 0 for no tool), which rs274 prints instead.
struct ChangeTool {  // M6
  int tool = 0;
  int slot = 0;
};
struct ChangeToolNumber {  // M61
  int tool = 0;
  int slot = 0;
};
// M428 (on) and M429 (off), as LinuxCNC's table-rotary sample configs remap them: tool
// centre point control, the programmed X Y Z the tool tip in the part's frame.
struct SetTcp {
  bool on = false;
};
struct SetFeedOverrideEnable {  // M50 and M48/M49
  bool on = true;
};
struct SetSpindleOverrideEnable {
  bool on = true;
};
struct SetAdaptiveFeedEnable {
  bool on = false;
};
struct SetFeedHoldEnable {
  bool on = true;
};
struct Comment {
  std::string text;
};
struct Message {  // (MSG,...) and (DEBUG,...)
  std::string text;
};
struct DebugMessage {
  std::string text;
};
struct ProgramStop {};          // M0
struct OptionalProgramStop {};  // M1
struct ProgramEnd {};           // M2/M30
struct PalletShuttle {};        // M60 (then a stop), M30
struct OnReset {};
struct Finish {};       // the program ended with a closing '%'
struct StartChange {};  // M6: the tool change begins (before ChangeTool)
// M19 R P (and G86/G87): the spindle stops and turns to `angle_deg` from its index, `mode` 0
// clockwise, 1 counterclockwise, 2 the shorter way (LinuxCNC's M19 P).
struct OrientSpindle {
  double angle_deg = 0;
  int mode = 0;
};
// M19 Q: the program waits at most `timeout_s` for the spindle to be oriented
// (SPINDLE.0.WAIT_ORIENT_COMPLETE).
struct WaitOrientSpindle {
  double timeout_s = 0;
};
// The program I/O indexes cncd has (config::kMaxDigitalIo, config::kMaxAnalogIo): M62-M66 P
// 0..31, M66-M68 E 0..15. Another index is an error at its line.
inline constexpr int kDigitalIoCount = 32;
inline constexpr int kAnalogIoCount = 16;

// M62/M63 (motion = true: with the start of the next move) and M64/M65 (at once, once the
// moves before have finished): DIGITAL_OUTPUT_index on or off.
struct SetOutputBit {
  int index = 0;
  bool on = false;
  bool motion = false;
};
// M67 (motion = true) and M68: ANALOG_OUTPUT_index set to value.
struct SetOutputValue {
  int index = 0;
  double value = 0;
  bool motion = false;
};
// M66: wait for DIGITAL_INPUT_index (digital) or ANALOG_INPUT_index. mode (L): 0 no wait (read
// now), 1 rising edge, 2 falling edge, 3 high, 4 low; an analog input is read at once (mode
// 0, timeout 0), as in LinuxCNC. timeout_s: Q when above 0, else 0. The machine's answer goes
// to #5399 (Interpreter::set_input_result()) before the interpreter reads on: a reader stops
// after this command until the machine has waited. LinuxCNC's rs274 prints nothing for it.
struct WaitInput {
  int index = 0;
  bool digital = true;
  int mode = 0;
  double timeout_s = 0;
};
// M100-M199: the executable found for it (InterpOptions::user_m_path), run with P and Q as its
// two arguments; an absent P or Q is -1, as LinuxCNC passes it.
struct UserMCode {
  int code = 0;
  double p = -1;
  double q = -1;
  std::string executable;  // absolute path
};
// G38.2-G38.5: TURN_PROBE_ON, a straight move at the feed that the machine ends where the
// probe trips (toward) or loses contact (away), TURN_PROBE_OFF. The machine reports where it
// tripped (Interpreter::set_probe_result) before the interpreter reads on.
enum class ProbeKind : std::uint8_t {
  toward_or_error = 0,  // G38.2: stop on contact; no contact is an error
  toward = 1,           // G38.3: stop on contact; no contact is no error
  away_or_error = 2,    // G38.4: stop on loss of contact; none is an error
  away = 3,             // G38.5
};
struct TurnProbeOn {};
struct TurnProbeOff {};
struct StraightProbe {  // STRAIGHT_PROBE(x, y, z, a, b, c)
  Pose end{};
  ProbeKind kind = ProbeKind::toward_or_error;
};
// G33, G33.1 (and rigid G84/G74): the moves between these follow the spindle's position,
// `feed_per_rev` (program units per revolution; machine units once to_machine() converted it)
// per turn. rs274 prints START_SPEED_FEED_SYNC(1.250000,0).
struct StartSpeedFeedSynch {
  double feed_per_rev = 0;
  bool velocity_mode = false;  // LinuxCNC's CSS velocity mode; false for G33/G33.1
};
struct StopSpeedFeedSynch {};
// G33.1: down to `end` in step with the spindle, the spindle reversed there, back up to the
// start in step with it, and the spindle's direction restored. RIGID_TAP(x, y, z).
struct RigidTap {
  Pose end{};
  double scale = 1.0;  // LinuxCNC's spindle speed scale for the way out
};
struct SetToolTableEntry {
  int pocket = 0;  // the tool's slot in the table (ChangeTool), 0 for the spindle
  int tool = 0;
  Pose offset{};  // tool table units
  double front_angle = 0;
  double back_angle = 0;
  int orientation = 0;
};

// The moves and the dwell come first.
using CanonOp =
    std::variant<StraightTraverse, StraightFeed, ArcFeed, NurbsFeed, Dwell, SetFeedRate,
                 SetFeedMode, SetFeedReference, SelectPlane, UseLengthUnits, SetG5xOffset,
                 SetG92Offset, SetXyRotation, UseToolLengthOffset, SetMotionControlMode,
                 SetNaivecamTolerance, StartSpindleClockwise, StartSpindleCounterclockwise,
                 StopSpindleTurning, SetSpindleSpeed, SetSpindleMode, MistOn, MistOff, FloodOn,
                 FloodOff, SelectTool, ChangeTool, ChangeToolNumber, SetFeedOverrideEnable,
                 SetSpindleOverrideEnable, SetAdaptiveFeedEnable, SetFeedHoldEnable, Comment,
                 Message, DebugMessage, ProgramStop, OptionalProgramStop, ProgramEnd, PalletShuttle,
                 OnReset, Finish, StartChange, OrientSpindle, WaitOrientSpindle, SetToolTableEntry,
                 SetOutputBit, SetOutputValue, WaitInput, UserMCode, TurnProbeOn, TurnProbeOff,
                 StraightProbe, StartSpeedFeedSynch, StopSpeedFeedSynch, RigidTap, SetTcp>;

// Whether every number in `op` is finite (an overflow shows as inf or NaN).
bool all_finite(const CanonOp& op);

struct CanonCommand {
  std::int32_t line = 0;  // 1-based source line number in its file
  CanonOp op;
};

// A visitor from lambdas: std::visit(Overloaded{[](const ArcFeed&) {...}, ...}, command.op).
template <class... Fs>
struct Overloaded : Fs... {
  using Fs::operator()...;
};
template <class... Fs>
Overloaded(Fs...) -> Overloaded<Fs...>;

// Receives canonical commands in program order. Called on the interpreter's thread.
class CanonSink {
 public:
  virtual ~CanonSink() = default;
  virtual void emit(const CanonCommand& command) = 0;
};

}  // namespace cncd::interp
