#include "probe_writer.hpp"

#include <unistd.h>

#include <utility>

namespace cncd::daemon {

QueuedProbeWriter::QueuedProbeWriter() : thread_([this] { work(); }) {}

QueuedProbeWriter::~QueuedProbeWriter() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  thread_.join();
  if (fd_ >= 0) ::close(fd_);
}

std::string QueuedProbeWriter::open(const interp::ProbeFileTarget& target,
                                    const std::string& where) {
  push(Op{Op::Kind::open, target, {}, where});
  return "";
}

std::string QueuedProbeWriter::write(const std::string& line, const std::string& where) {
  push(Op{Op::Kind::write, {}, line, where});
  return "";
}

void QueuedProbeWriter::close() {
  push(Op{Op::Kind::close, {}, {}, {}});
}

std::optional<std::string> QueuedProbeWriter::take_error() {
  std::lock_guard lock(mutex_);
  return std::exchange(error_, std::nullopt);
}

void QueuedProbeWriter::drain() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

void QueuedProbeWriter::push(Op op) {
  {
    std::lock_guard lock(mutex_);
    if (queue_.size() >= kMaxQueued) {
      if (!error_) error_ = op.where + ": Cannot write probe file: the disk does not keep up";
      return;
    }
    queue_.push_back(std::move(op));
  }
  wake_.notify_one();
}

void QueuedProbeWriter::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping, and all written
    const Op op = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    run(op);
    lock.lock();
    busy_ = false;
    if (queue_.empty()) idle_.notify_all();
  }
}

// Worker thread. After a failed open the lines of that file are dropped: the error ends the
// program, and a half-written file is no result.
void QueuedProbeWriter::run(const Op& op) {
  std::string problem;
  switch (op.kind) {
    case Op::Kind::open:
      if (fd_ >= 0) ::close(fd_);
      path_ = op.target.path().string();
      fd_ = interp::open_probe_file(op.target, problem);
      break;
    case Op::Kind::write:
      if (fd_ < 0) return;
      if (const auto why = interp::write_probe_text(fd_, op.text); !why.empty()) {
        problem = "Cannot write probe file " + path_ + ": " + why;
        ::close(fd_);
        fd_ = -1;
      }
      break;
    case Op::Kind::close:
      if (fd_ >= 0) ::close(fd_);
      fd_ = -1;
      break;
  }
  if (problem.empty()) return;
  std::lock_guard lock(mutex_);
  if (!error_) error_ = op.where + ": " + problem;
}

interp::InterpOptions with_probe_writer(interp::InterpOptions options,
                                        std::shared_ptr<interp::ProbeFileWriter> writer) {
  options.probe_writer = std::move(writer);
  return options;
}

}  // namespace cncd::daemon
