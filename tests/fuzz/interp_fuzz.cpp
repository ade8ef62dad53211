// libFuzzer target over the interpreter's lexer, parser, expression evaluator and executor:
// arbitrary bytes run as a program through the real Interpreter (or, when the first byte is
// odd, as MDI blocks one line at a time), every command converted to machine coordinates; bit 1
// of that byte makes the machine's units inches, bit 2 its dialect Numeryx.
// Any input must end in a clean error or a clean end: never a crash, hang or leak.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/to_machine.hpp"

namespace {

using namespace cncd::interp;

// Blocks executed per input: an O-word loop that never moves may run forever by design (as in
// LinuxCNC), so the harness bounds it; the interpreter's own limits are tested beyond it.
constexpr int kMaxBlocks = 20000;

class MachineSink final : public CanonSink {
 public:
  void emit(const CanonCommand& command) override {
    const CanonCommand out = tracker_.to_machine(command);
    checksum_ += std::visit(Overloaded{
                                [](const StraightTraverse& c) { return c.end[0]; },
                                [](const StraightFeed& c) { return c.end[0]; },
                                [](const ArcFeed& c) { return c.first_end; },
                                [](const Comment& c) { return static_cast<double>(c.text.size()); },
                                [](const Message& c) { return static_cast<double>(c.text.size()); },
                                [](const SetOutputValue& c) { return c.value; },
                                [](const UserMCode& c) { return c.p + c.q; },
                                [this](const WaitInput& c) {
                                  waited_ = true;
                                  return c.timeout_s;
                                },
                                [](const auto&) { return 0.0; },
                            },
                            out.op);
  }
  double checksum() const { return checksum_; }
  // An M66 ran: the machine's answer goes back before the next step, as the daemon's task
  // does it.
  bool take_wait() { return std::exchange(waited_, false); }

 private:
  MachineTracker tracker_;
  double checksum_ = 0;
  bool waited_ = false;
};

void run(Interpreter& interp, MachineSink& sink) {
  for (int blocks = 0; blocks < kMaxBlocks; ++blocks) {
    const auto step = interp.step(sink);
    if (step != Interpreter::Step::block) {
      if (step == Interpreter::Step::error && !interp.error()) __builtin_trap();
      return;
    }
    if (sink.take_wait()) interp.set_input_result(blocks % 3 == 0 ? -1.0 : blocks % 2);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool mdi = (data[0] & 1) != 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  InterpOptions options;
  options.machine_units = (data[0] & 2) != 0 ? Units::inches : Units::mm;
  options.dialect = (data[0] & 4) != 0 ? Dialect::numeryx : Dialect::linuxcnc;
  Interpreter interp(options);
  MachineSink sink;
  if (!mdi) {
    if (!interp.open_string(text, "fuzz.ngc")) run(interp, sink);
    return 0;
  }
  std::string_view rest = text;
  while (!rest.empty()) {
    const auto end = rest.find('\n');
    const std::string line(rest.substr(0, end));
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    if (!interp.open_mdi(line)) run(interp, sink);
  }
  (void)interp.state();
  return 0;
}
