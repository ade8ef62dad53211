// The probe results file, written on a thread of its own: the daemon's loop hands each line
// over and goes on, so that a slow or stuck disk never delays an estop. Opening refuses what
// is not a regular file without blocking (interp::open_probe_file), and a problem found there
// is reported back through take_error(), naming the program's file and line.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/probe_file.hpp"

namespace cncd::daemon {

class QueuedProbeWriter final : public interp::ProbeFileWriter {
 public:
  QueuedProbeWriter();
  // Writes what is queued, then ends the thread.
  ~QueuedProbeWriter() override;
  QueuedProbeWriter(const QueuedProbeWriter&) = delete;
  QueuedProbeWriter& operator=(const QueuedProbeWriter&) = delete;

  // Called on the loop thread; never wait for the disk.
  std::string open(const interp::ProbeFileTarget& target, const std::string& where) override;
  std::string write(const std::string& line, const std::string& where) override;
  void close() override;

  // The first problem since the last call ("FILE:LINE: Cannot open probe file ..."), if any.
  std::optional<std::string> take_error();
  // Waits until everything queued so far is written (tests, shutdown).
  void drain();

 private:
  struct Op {
    enum class Kind { open, write, close } kind;
    interp::ProbeFileTarget target;
    std::string text;
    std::string where;
  };
  void push(Op op);
  void work();
  void run(const Op& op);

  // A program probes a few times a second at most; a queue this long means the disk is stuck.
  static constexpr std::size_t kMaxQueued = 4096;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  // Guarded by mutex_:
  std::deque<Op> queue_;
  bool busy_ = false;
  bool stopping_ = false;
  std::optional<std::string> error_;
  // The worker's own:
  int fd_ = -1;
  std::string path_;
  std::thread thread_;
};

// `options` with their probe file written by `writer`.
interp::InterpOptions with_probe_writer(interp::InterpOptions options,
                                        std::shared_ptr<interp::ProbeFileWriter> writer);

}  // namespace cncd::daemon
