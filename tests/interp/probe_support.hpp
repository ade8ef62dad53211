// What the probe tests share: a sink that records, a scratch directory, and a run whose
// machine answers each probe.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "canon_recorder.hpp"
#include "cncd/interp/interpreter.hpp"

namespace cncd::interp {

struct Recorder final : test_support::CanonRecorder {
  void emit(const CanonCommand& command) override {
    CanonRecorder::emit(command);
    if (std::holds_alternative<StraightProbe>(command.op)) probed = true;
  }
  bool probed = false;  // a StraightProbe since the caller last looked
};

inline Pose pose(double x, double y, double z) {
  Pose p{};
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

// A scratch directory for one test.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("cncd-probe-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name) << text;
    return path_ / name;
  }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

inline std::string read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs a program whose machine answers each probe: the probe trips at `trips[n]` (machine
// coordinates) and stops 0.1 below it in Z. Returns the error text, "" at a clean end.
inline std::string run_answering(Interpreter& interp, Recorder& recorder,
                                 const std::vector<Pose>& trips) {
  std::size_t next = 0;
  for (;;) {
    const auto step = interp.step(recorder);
    if (step == Interpreter::Step::error) return interp.error()->to_string();
    if (step == Interpreter::Step::end) return "";
    if (recorder.probed) {
      recorder.probed = false;
      if (next < trips.size()) {
        const Pose trip = trips[next++];
        interp.set_probe_result(trip, true);
        Pose stop = trip;
        stop[2] -= 0.1;
        interp.set_machine_position(stop);
      }
    }
  }
}

}  // namespace cncd::interp
