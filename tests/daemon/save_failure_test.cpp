// Saves that fail: the real daemon with its state directory on a tiny tmpfs that is then filled
// up or made read-only. What cannot be saved is answered as an error and not kept, and no
// temporary file is left behind.
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>

#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class SaveFailureTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (geteuid() != 0) GTEST_SKIP() << "mounting a tmpfs as the state directory needs root";
    state_ = dir_.path() / "state";
    fs::create_directories(state_);
    // Room for the seeds, the marker, the position file and the job history, and a little more.
    // Mode 0755: a tmpfs is 1777 by default, a state directory cncd refuses.
    if (mount("tmpfs", state_.c_str(), "tmpfs", 0, "size=256k,mode=0755") != 0) {
      GTEST_SKIP() << "cannot mount a tmpfs on " << state_ << ": " << std::strerror(errno);
    }
    mounted_ = true;
    ini_ = copy_example_machine(dir_.path());
    ASSERT_EQ(daemon_.start(dir_.path(), {"--ini", ini_.string(), "--state-dir", state_.string()}),
              "");
    ASSERT_EQ(client_.connect(daemon_.socket()), "");
  }

  void TearDown() override {
    if (!mounted_) return;
    daemon_.kill_hard();
    umount2(state_.c_str(), MNT_DETACH);
  }

  json call(const std::string& method, const json& params = nullptr) {
    return client_.call(method, params, 30000);
  }

  // Runs the open program and returns the status once it has ended.
  json run_to_idle() {
    result_of(call("program.run"));
    json s;
    for (int i = 0; i < 3000; ++i) {
      s = result_of(call("status.get"));
      if (s["exec"] == "idle") break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return s;
  }

  // Waits until the event log has an event of `kind` whose message holds `text`.
  bool wait_for_event(const std::string& kind, const std::string& text) {
    json events;
    for (int i = 0; i < 3000; ++i) {
      events = result_of(call("errors.list"))["events"];
      for (const auto& e : events) {
        if (e["kind"] == kind && e["message"].get<std::string>().find(text) != std::string::npos)
          return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ADD_FAILURE() << "no " << kind << " event with '" << text << "' in " << events.dump();
    return false;
  }

  // Takes every free block of the tmpfs.
  void fill_disk() {
    std::ofstream filler(state_ / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    for (int i = 0; i < 1000 && filler.write(block.data(), block.size()); ++i) {
      filler.flush();
    }
    // One more small file for whatever a partial block left.
    std::ofstream(state_ / "filler2") << std::string(4096, 'y');
    ASSERT_FALSE(std::ofstream(state_ / "probe") << std::string(4096, 'z') << std::flush)
        << "the tmpfs is not full";
    fs::remove(state_ / "probe");
  }

  // A remount read-only is refused (EBUSY) while a file there is open for writing: at start
  // the job history opens jobs.db on its own thread (marking runs cut short), then closes it.
  void make_read_only() {
    int rc = -1;
    for (int i = 0; i < 1000; ++i) {
      rc = mount("tmpfs", state_.c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, "size=64k");
      if (rc == 0 || errno != EBUSY) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_EQ(rc, 0) << std::strerror(errno);
  }

  // The files in the state directory that are neither the state files nor the filler: a
  // temporary file left behind.
  std::vector<std::string> strays() const {
    const std::set<std::string> known = {
        "sim_mm.var",  "sim_mm.tbl", "sim_mm.position", "sim_mm.position.running",
        "cncd.lock",   "filler",     "filler2",         "jobs.db",
        "jobs.db-wal", "jobs.db-shm"};
    std::vector<std::string> out;
    for (const auto& entry : fs::directory_iterator(state_)) {
      if (!known.contains(entry.path().filename().string()))
        out.push_back(entry.path().filename().string());
    }
    return out;
  }

  json origin(const std::string& system) {
    const json offsets = result_of(call("offsets.get"));
    for (const auto& s : offsets["systems"]) {
      if (s["name"] == system) return s["origin"];
    }
    ADD_FAILURE() << "no " << system;
    return json();
  }

  void ready_machine() {
    result_of(call("machine.reset"));
    result_of(call("machine.on"));
    result_of(call("machine.home"));
    for (int i = 0; i < 3000; ++i) {
      const json s = result_of(call("status.get"));
      bool homed = s["motion"] == "idle";
      for (const auto& h : s["homed"])
        homed = homed && h.get<bool>();
      if (homed) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    FAIL() << "the machine did not home";
  }

  TempDir dir_;
  fs::path state_;
  fs::path ini_;
  bool mounted_ = false;
  DaemonProcess daemon_;
  daemon::Client client_;
};

// The answer to a request whose change could not be saved: error 1007.
void expect_not_saved(const json& answer) {
  EXPECT_EQ(error_code(answer), 1007) << answer.dump();
}

TEST_F(SaveFailureTest, OffsetsSetOnAFullDiskAnswers1007AndKeepsTheOldOrigin) {
  const json before = origin("G55");
  fill_disk();
  const json r = call("offsets.set", {{"system", "G55"}, {"origin", {{"x", 123.5}}}});
  EXPECT_EQ(error_code(r), 1007) << r.dump();
  EXPECT_NE(r.dump().find("No space left on device"), std::string::npos) << r.dump();
  EXPECT_EQ(origin("G55"), before);
  EXPECT_EQ(strays(), std::vector<std::string>{});
  // Room again: the same request is saved and kept.
  fs::remove(state_ / "filler");
  result_of(call("offsets.set", {{"system", "G55"}, {"origin", {{"x", 123.5}}}}));
  EXPECT_EQ(origin("G55")["x"], 123.5);
}

TEST_F(SaveFailureTest, OffsetsSetOnAReadOnlyDiskAnswers1007AndKeepsTheOldOrigin) {
  const json before = origin("G54");
  make_read_only();
  // The active system: the work position would move with it.
  const json status_before = result_of(call("status.get"));
  expect_not_saved(call("offsets.set", {{"system", "G54"}, {"origin", {{"x", -7}, {"z", 2}}}}));
  EXPECT_EQ(origin("G54"), before);
  const json status_after = result_of(call("status.get"));
  EXPECT_EQ(status_after["work_position"], status_before["work_position"]);
  EXPECT_EQ(status_after["offsets"]["g5x"], status_before["offsets"]["g5x"]);
  EXPECT_EQ(strays(), std::vector<std::string>{});
}

TEST_F(SaveFailureTest, ToolSetOnAFullDiskAnswers1007AndKeepsTheOldEntry) {
  const json before = result_of(call("tool.list"))["tools"];
  fill_disk();
  expect_not_saved(call("tool.set", {{"number", 2}, {"offset", {{"z", 42}}}}));
  EXPECT_EQ(result_of(call("tool.list"))["tools"], before);
  EXPECT_EQ(strays(), std::vector<std::string>{});
}

TEST_F(SaveFailureTest, MdiThatChangesOffsetsOrToolsOnAFullDiskFailsAndIsUndone) {
  ready_machine();
  const json g54 = origin("G54");
  const json tools = result_of(call("tool.list"))["tools"];
  fill_disk();
  // Nothing to save: a move works on a full disk.
  result_of(call("mdi.execute", {{"line", "G0 X1"}}));
  for (const char* line : {"G10 L2 P1 X7", "G10 L20 P1 X0", "G92 X3", "G55"}) {
    SCOPED_TRACE(line);
    const json r = call("mdi.execute", {{"line", line}});
    EXPECT_EQ(error_code(r), 1007) << r.dump();
    EXPECT_NE(r.dump().find("undone"), std::string::npos) << r.dump();
    const json s = result_of(call("status.get"));
    EXPECT_EQ(origin("G54"), g54);
    EXPECT_EQ(s["offsets"]["coord_system"], "G54");
    EXPECT_EQ(s["offsets"]["g92"]["x"], 0.0);
    EXPECT_NEAR(s["work_position"]["commanded"]["x"].get<double>(), 1.0 - g54["x"].get<double>(),
                1e-9);
  }
  expect_not_saved(call("mdi.execute", {{"line", "G10 L1 P2 Z55"}}));
  EXPECT_EQ(result_of(call("tool.list"))["tools"], tools);
  EXPECT_EQ(strays(), std::vector<std::string>{});
}

TEST_F(SaveFailureTest, ProgramThatSetsAnOffsetOnAFullDiskEndsInErrorAndIsUndone) {
  ready_machine();
  const json g56 = origin("G56");
  const fs::path program = dir_.write("g10.ngc", "G10 L2 P3 X11 Y12\nG0 X2\nM2\n");
  result_of(call("program.open", {{"path", program.string()}}));
  fill_disk();
  const json s = run_to_idle();
  EXPECT_EQ(s["program"]["result"], "error") << s.dump();
  const std::string error = s["program"]["error"];
  EXPECT_NE(error.find("sim_mm.var"), std::string::npos) << error;
  EXPECT_NE(error.find("No space left on device"), std::string::npos) << error;
  EXPECT_EQ(origin("G56"), g56);
  EXPECT_EQ(strays(), std::vector<std::string>{});
}

// The job history on a full disk: the run goes on, the problem is logged once, and the run's
// row is written when there is room again.
TEST_F(SaveFailureTest, AJobOnAFullDiskIsLoggedKeptAndWrittenWhenThereIsRoom) {
  ready_machine();
  const fs::path program = dir_.write("part.ngc", "G21 G90 F3000\nG1 X5\nM30\n");
  result_of(call("program.open", {{"path", program.string()}}));
  fill_disk();
  const json s = run_to_idle();
  EXPECT_EQ(s["program"]["result"], "done") << s.dump();
  EXPECT_TRUE(wait_for_event("jobs", "No space left on device"));
  EXPECT_EQ(s["state"], "on");
  // Even a read needs room for SQLite's shared-memory file: refused, saying why.
  const json full = call("jobs.history");
  EXPECT_EQ(error_code(full), 1012);
  EXPECT_NE(full.dump().find("No space left on device"), std::string::npos) << full.dump();
  fs::remove(state_ / "filler");
  fs::remove(state_ / "filler2");
  EXPECT_TRUE(wait_for_event("jobs", "written again"));
  const json jobs = result_of(call("jobs.history"))["jobs"];
  ASSERT_EQ(jobs.size(), 1u) << jobs.dump();
  EXPECT_EQ(jobs[0]["result"], "done");
  EXPECT_EQ(jobs[0]["parts"], 1);
  EXPECT_EQ(jobs[0]["program"], program.string());
}

}  // namespace
}  // namespace cncd::test
