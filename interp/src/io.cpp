// Program I/O: M62-M65 digital outputs, M66 waiting for an input, M67/M68 analog outputs, and
// the user M codes M100-M199, with LinuxCNC's checks and wording.
#include <cmath>
#include <filesystem>
#include <string>
#include <system_error>

#include "failure.hpp"
#include "interp_state.hpp"

namespace cncd::interp {
namespace {

// LinuxCNC's round_to_int: to the nearest integer, halves to even.
int round_to_int(double value) {
  return to_int(std::nearbyint(value));
}

std::string out_of_range(const char* what, int index, int count) {
  return std::string(what) + ": " + std::to_string(index) + " not in [0.." +
         std::to_string(count - 1) + "]";
}

// The executable LinuxCNC's task would run for M`code`: a regular file named exactly
// "M1nn" (capital M) that its owner may execute, in the first directory that has one.
std::filesystem::path find_user_m_code(const std::vector<std::filesystem::path>& dirs, int code) {
  const std::string name = "M" + std::to_string(code);
  for (const auto& dir : dirs) {
    if (dir.empty()) continue;
    const std::filesystem::path path = dir / name;
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::is_regular_file(status)) continue;
    if ((status.permissions() & std::filesystem::perms::owner_exec) ==
        std::filesystem::perms::none) {
      continue;
    }
    const auto absolute = std::filesystem::absolute(path, ec);
    return ec ? path : absolute.lexically_normal();
  }
  return {};
}

}  // namespace

// LinuxCNC 2.9's convert_m reads P, E and Q as given: an absent P or Q is -1.
void Interpreter::Impl::do_io() {
  const int code = block_.m_code(MGroup::io);
  if (code < 0) return;
  const int column = block_.m_column[static_cast<std::size_t>(MGroup::io)];
  const std::string name = "M" + std::to_string(code);
  const double q = block_.has('q') ? block_.get('q') : -1.0;
  if (comp_.on()) {
    const char* what = code == 62                                ? "set motion output"
                       : code == 63                              ? "set motion digital output"
                       : code <= 65                              ? "set auxiliary digital output"
                       : code == 67                              ? "set motion analog output"
                       : code == 68                              ? "set auxiliary analog output"
                       : block_.has('e') && block_.get('e') >= 0 ? "wait for analog input"
                                                                 : "wait for digital input";
    fail(std::string("Cannot ") + what + " with cutter radius compensation on", column);
  }
  if (code >= 62 && code <= 65) {
    if (!block_.has('p')) fail("No valid P word with " + name, column);
    const int index = round_to_int(block_.get('p'));
    if (index < 0 || index >= kDigitalIoCount) {
      fail(out_of_range(("Digital output index out of range with " + name).c_str(), index,
                        kDigitalIoCount),
           block_.col('p'));
    }
    emit(SetOutputBit{index, code == 62 || code == 64, code <= 63});
    return;
  }
  if (code == 67 || code == 68) {
    const std::string invalid = "Invalid analog index with " + name;
    if (!block_.has('e') || round_to_int(block_.get('e')) < 0) fail(invalid, column);
    const int index = round_to_int(block_.get('e'));
    if (index >= kAnalogIoCount) {
      fail(out_of_range(invalid.c_str(), index, kAnalogIoCount), block_.col('e'));
    }
    emit(SetOutputValue{index, q, code == 67});
    return;
  }
  // M66: P digital input or E analog input, L wait mode, Q timeout.
  const bool has_p = block_.has('p');
  const bool has_e = block_.has('e');
  const bool has_l = block_.has('l');
  const int mode = has_l ? to_int(block_.get('l')) : 0;
  if (has_p && has_e) {
    fail("Invalid to select both a digital and an analog input with M66", column);
  }
  if (q <= 0 && has_l && mode > 0) {
    fail("Zero timeout with wait type != immediate return", column);
  }
  if (has_e && has_l && mode != 0) {
    fail("Can't select analog input with wait type != immediate return", column);
  }
  if ((has_p && round_to_int(block_.get('p')) < 0) ||
      (has_e && round_to_int(block_.get('e')) < 0) || (!has_p && !has_e)) {
    fail("Need to have either a valid P or a valid E word with M66", column);
  }
  if (has_p) {
    // LinuxCNC's task knows these five; it reports any other only when the wait runs.
    if (mode > 4) {
      fail(out_of_range("Unknown Wait Mode with M66 (0 immediate, 1 rise, 2 fall, 3 high, 4 low)",
                        mode, 5),
           block_.col('l'));
    }
    const int index = round_to_int(block_.get('p'));
    if (index >= kDigitalIoCount) {
      fail(out_of_range("Digital input selected out of bounds", index, kDigitalIoCount),
           block_.col('p'));
    }
    emit(WaitInput{index, true, mode, q > 0 ? q : 0.0});
  } else {
    const int index = round_to_int(block_.get('e'));
    if (index >= kAnalogIoCount) {
      fail(out_of_range("Analog input selected out of bounds", index, kAnalogIoCount),
           block_.col('e'));
    }
    emit(WaitInput{index, false, 0, 0.0});
  }
  input_pending_ = true;
  input_digital_ = has_p;
}

// After an M66, LinuxCNC reads the input into #5399 before it reads the next line. Without
// a machine to answer (set_input_result()), its standalone interpreter's answer is what #5399
// held: as a digital value 0 or 1, or unchanged for an analog input.
void Interpreter::Impl::read_input_result() {
  if (!input_pending_) return;
  input_pending_ = false;
  if (input_digital_) parameters_.set(5399, parameters_.get(5399) != 0.0 ? 1.0 : 0.0);
}

void Interpreter::Impl::do_user_m_code() {
  const int code = block_.m_code(MGroup::user);
  if (code < 0) return;
  if (code == 428 || code == 429) {
    // Not user programs: the machine's TCP switch (docs/kinematics.md). The program goes on
    // from where the tool stands, in the frame switched to: LinuxCNC's remaps read the
    // position back after switching the kinematics.
    const bool on = code == 428;
    if (options_.tcp_switch) {
      if (comp_.on()) {
        fail("Cannot switch TCP (M" + std::to_string(code) + ") with cutter radius compensation on",
             block_.m_column[static_cast<std::size_t>(MGroup::user)]);
      }
      Pose machine = program_to_machine(pos_);
      for (std::size_t axis = 0; axis < kAxes; ++axis) {
        if (is_linear_axis(static_cast<int>(axis))) machine[axis] = to_machine_units(machine[axis]);
      }
      Pose moved = options_.tcp_switch(machine, on);
      if (moved != machine) {
        for (std::size_t axis = 0; axis < kAxes; ++axis) {
          if (is_linear_axis(static_cast<int>(axis))) moved[axis] = to_program_units(moved[axis]);
        }
        pos_ = machine_to_program(moved);
      }
    }
    emit(SetTcp{on});
    return;
  }
  const auto executable = find_user_m_code(options_.user_m_path, code);
  if (executable.empty()) {
    fail("Unknown m code used: M" + std::to_string(code),
         block_.m_column[static_cast<std::size_t>(MGroup::user)]);
  }
  emit(UserMCode{code, block_.has('p') ? block_.get('p') : -1.0,
                 block_.has('q') ? block_.get('q') : -1.0, executable.string()});
}

}  // namespace cncd::interp
