// MotionController: owns the planner, the servo thread and the drivers.
//
// Threads: the task thread calls every public method; the servo thread is internal. Status is
// read lock-free (seqlock) from any thread.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "cncd/config/machine_config.hpp"
#include "cncd/motion/status.hpp"
#include "cncd/motion/types.hpp"

namespace cncd::motion {

class MotionController {
 public:
  explicit MotionController(const config::MachineConfig& config);
  ~MotionController();
  MotionController(const MotionController&) = delete;
  MotionController& operator=(const MotionController&) = delete;

  // Creates and configures the drivers and starts the servo thread. Returns "" or an error.
  // When SCHED_FIFO or mlockall is refused, logs one warning and runs anyway.
  std::string start();
  // Stops motion, disables the drives, joins the servo thread. Idempotent.
  void stop();

  // Queues one move (planned here, on the caller's thread). False when the segment queue is
  // full: call again later. Moves are refused (false) while the machine is not on.
  bool enqueue(const Move& move);
  // Free slots in the segment queue.
  std::size_t queue_space() const;

  // Priority commands: they bypass queued motion.
  void estop();          // latch estop: stop within one period, drives disabled
  void reset_estop();    // leave estop (machine stays off)
  void machine_on();     // enable drives (needs estop reset)
  void machine_off();    // controlled stop, disable drives
  void home(std::uint32_t joint_mask);  // home these joints (all-ones = all in HOME_SEQUENCE)
  void abort();          // controlled stop, flush queued motion
  void pause();          // feed hold: controlled stop on the path
  void resume();
  void clear_fault();

  // Lock-free copy of the latest status.
  Status status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cncd::motion
