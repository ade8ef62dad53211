// The small interface every joint driver implements (sim, gpio step/dir, modbus).
//
// Lifecycle: configure() (non-RT, may allocate, may fail with a message) -> enable() ->
// write()/read() once per servo period (RT) -> disable() -> destructor (non-RT).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/drivers/rt.hpp"

namespace cncd::drivers {

inline constexpr int kMaxJoints = config::kMaxJoints;

// What the servo thread hands a driver each period, one entry per joint it owns.
struct JointCommand {
  double position = 0;  // joint units (mm, inch or degrees)
  double velocity = 0;  // joint units/s, feed-forward
  bool enable = false;
  // The servo cycle that computed this command: 1 for the first, one more each period. A
  // driver whose feedback comes back later than the next period hands it back in
  // JointFeedback::command_cycle.
  std::uint64_t cycle = 0;
};

// What a driver reports each period.
struct JointFeedback {
  double position = 0;  // joint units
  bool home_switch = false;
  bool min_limit = false;
  bool max_limit = false;
  bool fault = false;  // drive reports a fault
  bool stale = false;  // no fresh feedback within the driver's deadline
  // Which commands `position` answers, by their cycle (JointCommand::cycle). command_cycle is
  // the latest command the drive had been given when the position was measured; 0 means the
  // latest command written (sim, gpio). previous_cycle is the newest command it had been given
  // long enough before to have followed it (Modbus: an update period; 0: the same as
  // command_cycle): a drive given a new target only now and then, and read right after, has
  // hardly begun to follow the newest. The following error is the distance from `position` to
  // the nearest point between those two commands, not to the latest command, so that a drive
  // whose feedback is late, or whose targets come late, is not charged with the distance its
  // command travelled meanwhile.
  std::uint64_t command_cycle = 0;
  std::uint64_t previous_cycle = 0;
};

struct MachineInputs {
  bool estop = false;  // external estop input asserted
  bool probe = false;
};

inline constexpr int kMaxDigitalIo = config::kMaxDigitalIo;
inline constexpr int kMaxAnalogIo = config::kMaxAnalogIo;

// The spindle as the servo thread commands it each period.
struct SpindleCommand {
  bool enable = false;   // turning
  bool reverse = false;  // M4
  double rpm = 0;        // >= 0: the speed to turn at (override applied, within the limits)
  // One more for every change of enable, reverse or rpm: the driver hands back the newest one
  // that had reached the drive when it took a reading (SpindleFeedback::acknowledged).
  std::uint64_t sequence = 0;
};

// The machine's outputs as the servo thread commands them each period. A driver writes the
// signals the config gives it (config::SignalAddress) and leaves the others alone.
struct IoCommand {
  SpindleCommand spindle;
  bool flood = false;
  bool mist = false;
  std::uint32_t digital = 0;                  // bit n: DIGITAL_OUTPUT_n
  std::array<double, kMaxAnalogIo> analog{};  // ANALOG_OUTPUT_n
  std::uint32_t panel = 0;                    // bit (1 << config::PanelLight): lit
};

// The spindle as its driver reports it.
struct SpindleFeedback {
  bool present = false;       // filled in by the spindle's driver
  double rpm = 0;             // actual speed, >= 0 (measured, simulated or after the ramp)
  bool has_at_speed = false;  // the drive reports at-speed itself (a VFD's status bit)
  bool at_speed = false;
  bool fault = false;         // the drive reports a fault (fault_reason() says which)
  bool stale = false;         // no fresh answer from the drive within its deadline
  bool has_position = false;  // an encoder: revolutions counts the spindle's position
  double revolutions = 0;
  // When the spindle stood at `revolutions`, by the driver's clock (only differences count): a
  // spindle that turns by the clock, not in servo periods, moves more over a period that came
  // late. 0: the position moves in servo periods (the simulated spindle).
  std::int64_t time_ns = 0;
  // How long a speed command takes to reach the spindle, on average (a field bus's update
  // period): commands already sent still turn it that long. 0: at once.
  std::int64_t command_delay_ns = 0;
  // The newest command (SpindleCommand::sequence) that had reached the drive before this
  // reading was taken: a Modbus drive's reading read after that command was written; the sim
  // and gpio spindles' reading of a period run with it. A reading older than the command says
  // nothing about whether the spindle has reached it.
  std::uint64_t acknowledged = 0;
};

// The panel's inputs ([PANEL], config::PanelConfig) as the drivers read them this period,
// before debouncing; a driver sets or clears the bits and values of the signals it owns.
struct PanelFeedback {
  std::uint64_t inputs = 0;  // bit (1 << config::PanelInput): the level, active-low applied
  // config::PanelCounter: the counter as it stands, wrapping at counter_bits (16 for a Modbus
  // register, 32 for a decoded encoder or a sim signal; 0: no driver owns it).
  std::array<std::uint32_t, config::kPanelCounters> counts{};
  std::array<std::uint8_t, config::kPanelCounters> counter_bits{};
  std::array<double, config::kPanelAnalogs> analog{};  // config::PanelAnalog, as read
};

// The machine's inputs as the drivers report them each period; a driver fills in the signals
// the config gives it and leaves the others alone.
struct IoFeedback {
  SpindleFeedback spindle;
  PanelFeedback panel;
  std::uint32_t digital = 0;                  // bit n: DIGITAL_INPUT_n
  std::array<double, kMaxAnalogIo> analog{};  // ANALOG_INPUT_n
};

enum Capability : std::uint32_t {
  kCapPositionFeedback = 1u << 0,  // feedback comes from the drive, not an echo
  kCapHomeSwitch = 1u << 1,
  kCapLimitSwitches = 1u << 2,
  kCapEstopInput = 1u << 3,
};

// Something that happened to a driver's devices off the servo thread (a pendant unplugged, or
// back), for the daemon to log.
struct DriverNotice {
  enum class Level : std::uint8_t { info, warning };
  Level level = Level::info;
  std::string text;
};

class Driver {
 public:
  virtual ~Driver() = default;
  Driver() = default;
  Driver(const Driver&) = delete;
  Driver& operator=(const Driver&) = delete;

  // Non-RT. Prepares hardware for the given joints; returns an error message or "" on success.
  virtual std::string configure(const config::MachineConfig& machine,
                                const std::vector<int>& joints) = 0;
  // Non-RT. Called before the servo thread starts / after it stops.
  virtual void enable() = 0;
  virtual void disable() = 0;
  // RT, servo thread: hand over this period's commands (indexed like configure()'s joints).
  CNCD_RT virtual void write(const JointCommand* commands, int count) noexcept = 0;
  // RT, servo thread: fill this period's feedback (indexed like configure()'s joints).
  CNCD_RT virtual void read(JointFeedback* feedback, int count) noexcept = 0;
  // RT, servo thread: machine-wide inputs; drivers without inputs leave them alone.
  CNCD_RT virtual void read_inputs(MachineInputs& /*inputs*/) noexcept {}
  // RT, servo thread: hand over this period's spindle and output commands. A driver acts on
  // the signals the config names with its kind (and the spindle when [SPINDLE_0] DRIVER
  // names it) and ignores the rest; it never blocks (I/O threads take the values).
  CNCD_RT virtual void write_io(const IoCommand& /*command*/) noexcept {}
  // RT, servo thread: fill in the spindle feedback and the inputs this driver owns.
  CNCD_RT virtual void read_io(IoFeedback& /*feedback*/) noexcept {}
  // RT-safe, any thread: copies into `out` (NUL-terminated) why the driver last reported a
  // fault, naming the drive, register or line; returns false (and an empty text) when it has
  // nothing to say. The text stays until the fault is reset.
  CNCD_RT virtual bool fault_reason(char* out, std::size_t size) const noexcept {
    if (size > 0) out[0] = '\0';
    return false;
  }
  // RT-safe, any thread: field-bus requests that failed since enable() (timeouts, exceptions,
  // lost links, failed connects); 0 for a driver without a bus.
  CNCD_RT virtual std::uint64_t exchange_errors() const noexcept { return 0; }
  // Non-RT, after configure(): how long ago (ns) the command that feedback not yet stale
  // answers may have been written; 0 when feedback always answers the latest command. The
  // servo loop keeps that many periods of commands to compare late feedback with.
  virtual std::int64_t feedback_deadline_ns() const noexcept { return 0; }
  // Non-RT, any thread but the servo thread: takes the oldest notice not yet taken; false
  // when there is none.
  virtual bool take_notice(DriverNotice& /*out*/) { return false; }
  virtual std::uint32_t capabilities() const noexcept = 0;
  virtual const char* name() const noexcept = 0;
};

// Non-RT. Creates the driver named by a joint's DRIVER key, or returns nullptr and sets error.
std::unique_ptr<Driver> make_driver(const std::string& name, std::string& error);

// A configured driver and the joints it drives, in joint order.
struct DriverInstance {
  std::unique_ptr<Driver> driver;
  std::vector<int> joints;
};

// Non-RT. The machine's drivers: one instance per DRIVER name among the config's joints, the
// spindle's DRIVER and the kinds of the signal addresses, configured for its joints (none for
// a driver that only drives the spindle or signals). Returns them, or nothing and sets `error`
// ("driver 'modbus': ...") when one cannot be made or configured.
std::vector<DriverInstance> make_drivers(const config::MachineConfig& config, std::string& error);

// The drivers the spindle and the signal addresses need ("gpio", "modbus", "sim"), joints aside:
// the panel's addresses count too. `evdev:` addresses are not among them: make_drivers adds the
// evdev driver for them (uses_evdev()).
std::vector<const char*> io_driver_names(const config::MachineConfig& config);

}  // namespace cncd::drivers
