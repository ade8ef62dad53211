// libFuzzer target over the control protocol's request path: an input is what one client sends
// on the socket. It is cut into lines as the server cuts it (server.cpp: '\n' ends a line, a
// trailing '\r' and blank lines are dropped, an unterminated last line is never served), and
// each line goes through the daemon's own RpcDispatcher::handle_line, with every method
// registered by register_methods over a real Task driving the simulated machine of
// config/examples/sim_mm.ini. Each line must get exactly one well-formed answer for each
// request with an id (none for notifications) carrying that id (rpc_answers.cpp), answers
// deferred to later (mdi.execute, program.abort) must each arrive once, no handler may fail
// with an internal error, and nothing may throw out of the dispatcher, crash, leak or hit
// undefined behaviour. rpc_mutator.cpp changes the values inside requests; rpc.dict holds the
// protocol's words.
//
// Input conventions of this harness:
// - "@PROGRAMS@" in a line stands for the directory of the test programs below (kPrograms),
//   which lives in a temporary directory whose name changes from run to run.
// - A first line "#read" makes the input a connection of the read group.
//
// What is left out, and why:
// - Lines that open a program other than the test programs are skipped: the checker would
//   read whatever file the path names where the fuzzer runs (a build tree holds files of many
//   megabytes), and the program checker and interpreter have a fuzzer of their own.
// - Homing is not needed to run programs and MDI (NO_FORCE_HOMING = 1 here): homing the sim
//   machine takes a few tenths of a second of servo time, which would cap the fuzzer at a
//   few inputs a second; machine.home itself is still served and runs.
//
// Motion runs for real: the servo thread runs in real time as in the daemon, so homing, jogs,
// MDI blocks and programs go on while the later lines of the input are served (whether a move
// is still under way when the next line comes depends on timing; motion/ and drivers/ are not
// instrumented for coverage, see standalone/CMakeLists.txt). Between inputs the machine goes
// back to where it started, so that what an input meets depends on nothing before it and a
// failure reproduces from its input alone. An input whose commands only switched the machine
// on or off or set overrides ends with an estop and the overrides at 1.0. One that reached any
// other command (a method of the control group that neither the dispatcher nor its handler
// refused, or a notification, whose outcome is not told) or left an event is followed by a
// new Task on fresh state files: in estop, unhomed, at 0, no program open, the shipped offsets
// and tool table. Answers still owed at the end of an input are collected after an estop.
#include <stdlib.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <thread>

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include "cncd/config/machine_config.hpp"
#include "event_log.hpp"
#include "jog_heartbeat.hpp"
#include "methods.hpp"
#include "rpc.hpp"
#include "rpc_answers.hpp"
#include "state_files.hpp"
#include "task.hpp"

namespace {

using namespace cncd;
using fuzz::Expectation;
using fuzz::fail;
using nlohmann::json;

constexpr std::string_view kProgramsToken = "@PROGRAMS@";
// Longest wait for the answers still owed once the machine is in estop.
constexpr auto kAnswerWait = std::chrono::seconds(5);

struct TestProgram {
  const char* name;
  const char* text;
};
constexpr TestProgram kPrograms[] = {
    {"ok.ngc", "G21 G90\nG0 X1 Y1\nG1 X2 F600\nM2\n"},
    {"stops.ngc", "G21 G90\nG0 X5\nM0\nG1 X0 Y5 F1200\nM1\nG4 P0.01\nG0 Z5\nM2\n"},
    {"long.ngc", "G21 G90\nG1 X200 Y150 F3000\nG2 X0 Y150 I-100 J0\nG0 X0 Y0\nM2\n"},
    {"limits.ngc", "G21 G90\nG0 X1000\nM2\n"},
    {"no_feed.ngc", "G21 G90\nG1 X1\nM2\n"},
    {"syntax.ngc", "G21\nG0 X[1+\nM2\n"},
    {"empty.ngc", ""},
};

[[noreturn]] void setup_failure(const std::string& what) {
  std::fprintf(stderr, "rpc_fuzz: cannot set up: %s\n", what.c_str());
  std::exit(1);
}

// The daemon's composition (cncd_main.cpp serve()) without the socket.
struct World {
  explicit World(const config::MachineConfig& config) : task(config, events, completions) {
    if (const auto error = task.load_files(); !error.empty()) setup_failure(error);
    if (const auto error = task.start(); !error.empty()) setup_failure(error);
    daemon::register_methods(dispatcher, task, config, events, completions, heartbeats);
  }
  // A jog or program stops at once rather than under control.
  ~World() { task.estop(); }
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  daemon::EventLog events;
  daemon::Completions completions;
  daemon::Task task;
  daemon::JogHeartbeats heartbeats{task, events};
  daemon::RpcDispatcher dispatcher;
};

struct Harness {
  std::filesystem::path dir;       // temporary: the state directory and the programs
  std::filesystem::path programs;  // what "@PROGRAMS@" stands for
  config::MachineConfig config;
  std::unique_ptr<World> world;
  // What the inputs did, told at exit.
  std::uint64_t inputs = 0;
  std::uint64_t skipped_lines = 0;  // opened a program elsewhere
  std::uint64_t put_back = 0;       // ended with estop or overrides at 1.0
  std::uint64_t rebuilt = 0;        // needed a new world

  ~Harness() {
    if (inputs > 0) {
      std::fprintf(stderr,
                   "rpc_fuzz: %llu inputs: %llu ended in a new machine, %llu put back by estop "
                   "or overrides; %llu lines skipped (program.open elsewhere)\n",
                   static_cast<unsigned long long>(inputs),
                   static_cast<unsigned long long>(rebuilt),
                   static_cast<unsigned long long>(put_back),
                   static_cast<unsigned long long>(skipped_lines));
    }
    world.reset();
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }

  void fresh_world() {
    world.reset();
    std::error_code ec;
    for (const auto& file : {config.parameter_file, config.tool_table, config.position_file})
      std::filesystem::remove(file, ec);
    std::vector<daemon::StateNote> notes;
    if (const auto error = daemon::prepare_state_files(config, notes); !error.empty())
      setup_failure(error);
    world = std::make_unique<World>(config);
  }
};

std::unique_ptr<Harness> harness;

std::filesystem::path make_temp_dir() {
  std::error_code ec;
  const std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                         ? std::filesystem::path("/dev/shm")
                                         : std::filesystem::temp_directory_path();
  std::string name = (base / "cncd-rpc-fuzz.XXXXXX").string();
  if (mkdtemp(name.data()) == nullptr) setup_failure("mkdtemp in " + base.string());
  return name;
}

void substitute_programs(std::string& line, const std::string& programs) {
  for (auto at = line.find(kProgramsToken); at != std::string::npos;
       at = line.find(kProgramsToken, at + programs.size()))
    line.replace(at, kProgramsToken.size(), programs);
}

// A program.open of a file outside the test programs' directory.
bool opens_elsewhere(const Expectation& expected, const std::string& programs) {
  if (expected.line_error) return false;
  const auto outside = [&](const json& request) {
    if (!request.is_object() || request.value("method", json()) != "program.open") return false;
    const auto params = request.find("params");
    if (params == request.end() || !params->is_object()) return false;
    const auto path = params->find("path");
    if (path == params->end() || !path->is_string()) return false;
    const auto& text = path->get_ref<const std::string&>();
    return !text.empty() &&
           (!text.starts_with(programs + "/") || text.find("..") != std::string::npos);
  };
  if (!expected.parsed.is_array()) return outside(expected.parsed);
  for (const auto& request : expected.parsed) {
    if (outside(request)) return true;
  }
  return false;
}

// What the requests of an input may have changed, and so what puts the world back as it was.
struct Changes {
  bool machine = false;    // on/off/estop state: an estop puts it back
  bool overrides = false;  // setting them to 1.0 puts them back
  bool other = false;      // anything else: only a new world puts it back
};

// A command counts once it has reached its handler and was not refused there (a refusal, 1001
// and up or -32602, changes nothing), or when it was a notification, whose outcome is not told.
void note_changes(const Expectation& expected, Changes& changes) {
  for (const auto& request : expected.requests) {
    if (!request.control || (request.answered && !request.deferred && request.answer_error))
      continue;
    if (request.method.starts_with("override.")) {
      changes.overrides = true;
    } else if (request.method == "machine.estop" || request.method == "machine.reset" ||
               request.method == "machine.on" || request.method == "machine.off") {
      changes.machine = true;
    } else {
      changes.other = true;
    }
  }
}

// Answers posted later go to the requests filed for them, each once (Server::deliver_completions).
void deliver(World& world, daemon::Session& session, std::set<std::uint64_t>& delivered) {
  for (const auto& done : world.completions.take()) {
    if (!delivered.insert(done.token).second)
      fail("a deferred answer was posted twice", "token " + std::to_string(done.token),
           done.error_message);
    auto& open = session.open_requests;
    const auto it = std::find_if(open.begin(), open.end(),
                                 [&](const auto& entry) { return entry.first == done.token; });
    // A notification's deferred answer is dropped, as the server drops it.
    if (it == open.end()) continue;
    fuzz::check_completion(done.error_code, done.error_message, it->second);
    open.erase(it);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Errors are kept, not printed: the last few go with a failure's report.
  auto tail = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(4);
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("cncd", tail));
  spdlog::set_level(spdlog::level::err);
  harness = std::make_unique<Harness>();
  Harness& h = *harness;
  h.dir = make_temp_dir();
  h.programs = h.dir / "programs";
  std::filesystem::create_directories(h.programs);
  for (const auto& program : kPrograms) {
    std::ofstream out(h.programs / program.name, std::ios::binary);
    out << program.text;
    if (!out.flush()) setup_failure("cannot write " + (h.programs / program.name).string());
  }
  config::LoadOptions options;
  options.state_dir = h.dir / "state";
  auto loaded = config::load_machine_config(CNCD_FUZZ_INI, options);
  if (!loaded.ok()) setup_failure(loaded.problems.front().to_string());
  h.config = std::move(*loaded.config);
  h.config.no_force_homing = true;
  h.fresh_world();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Harness& h = *harness;
  World& world = *h.world;
  ++h.inputs;
  std::string_view input(reinterpret_cast<const char*>(data), size);
  daemon::Session session;
  session.access = daemon::Access::control;
  constexpr std::string_view kReadOnly = "#read\n";
  if (input.starts_with(kReadOnly)) {
    session.access = daemon::Access::read;
    input.remove_prefix(kReadOnly.size());
  }
  const std::uint64_t events_before = world.events.last_seq();
  const std::string programs = h.programs.string();
  std::set<std::uint64_t> delivered;
  Changes changes;
  for (auto newline = input.find('\n'); newline != std::string_view::npos;
       newline = input.find('\n')) {
    std::string line(input.substr(0, newline));
    input.remove_prefix(newline + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    substitute_programs(line, programs);
    Expectation expected = fuzz::expect(line);
    if (opens_elsewhere(expected, programs)) {
      ++h.skipped_lines;
      continue;
    }
    const std::size_t open_before = session.open_requests.size();
    std::optional<std::string> answer;
    try {
      answer = world.dispatcher.handle_line(line, session);
    } catch (const std::exception& e) {
      fail(std::string("an exception left the dispatcher: ") + e.what(), line, "(none)");
    } catch (...) {
      fail("an exception left the dispatcher", line, "(none)");
    }
    std::vector<json> deferred;
    for (std::size_t i = open_before; i < session.open_requests.size(); ++i)
      deferred.push_back(session.open_requests[i].second);
    fuzz::check_answer(line, answer, expected, deferred);
    if (session.access == daemon::Access::read) {
      for (const auto& request : expected.requests) {
        if (request.control && request.answered && (request.deferred || !request.answer_error))
          fail("a connection of the read group ran a command", line, answer.value_or("(none)"));
      }
    }
    note_changes(expected, changes);
    world.task.poll();
    deliver(world, session, delivered);
  }
  if (!session.open_requests.empty()) {
    world.task.estop();
    const auto deadline = std::chrono::steady_clock::now() + kAnswerWait;
    for (;;) {
      world.task.poll();
      deliver(world, session, delivered);
      if (session.open_requests.empty()) break;
      if (std::chrono::steady_clock::now() > deadline)
        fail("a deferred request got no answer within 5 s of estop",
             "id " + session.open_requests.front().second.dump(), "(none)");
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  if (changes.other || world.events.last_seq() != events_before) {
    ++h.rebuilt;
    h.fresh_world();
    return 0;
  }
  h.put_back += changes.machine || changes.overrides;
  if (changes.machine) world.task.estop();
  if (changes.overrides) {
    world.task.set_feed_override(1.0);
    world.task.set_rapid_override(1.0);
    world.task.set_spindle_override(1.0);
  }
  return 0;
}
