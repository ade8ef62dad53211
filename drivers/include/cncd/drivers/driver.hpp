// The small interface every joint driver implements (sim, gpio step/dir, modbus).
//
// Lifecycle: configure() (non-RT, may allocate, may fail with a message) -> enable() ->
// write()/read() once per servo period (RT) -> disable() -> destructor (non-RT).
#pragma once

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

enum Capability : std::uint32_t {
  kCapPositionFeedback = 1u << 0,  // feedback comes from the drive, not an echo
  kCapHomeSwitch = 1u << 1,
  kCapLimitSwitches = 1u << 2,
  kCapEstopInput = 1u << 3,
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
  // RT-safe, any thread: copies into `out` (NUL-terminated) why the driver last reported a
  // fault, naming the drive, register or line; returns false (and an empty text) when it has
  // nothing to say. The text stays until the fault is reset.
  CNCD_RT virtual bool fault_reason(char* out, std::size_t size) const noexcept {
    if (size > 0) out[0] = '\0';
    return false;
  }
  // Non-RT, after configure(): how long ago (ns) the command that feedback not yet stale
  // answers may have been written; 0 when feedback always answers the latest command. The
  // servo loop keeps that many periods of commands to compare late feedback with.
  virtual std::int64_t feedback_deadline_ns() const noexcept { return 0; }
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

// Non-RT. The machine's drivers: one instance per DRIVER name among the config's joints,
// configured for its joints. Returns them, or nothing and sets `error` ("driver 'modbus': ...")
// when one cannot be made or configured.
std::vector<DriverInstance> make_drivers(const config::MachineConfig& config, std::string& error);

}  // namespace cncd::drivers
