// G38.x in the servo loop, in virtual time, with the simulated driver's probe model: a probing
// move stops in the period the probe trips, latches where the machine was then, decelerates
// within the limits, and reports no contact, a probe tripped at the start and an abort.
#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cncd/config/ini_file.hpp"
#include "machine_fixture.hpp"

namespace cncd::test {
namespace {

using motion::Move;
using motion::ProbeMode;
using motion::RtEvent;

// The small mill with a simulated block whose top is at Z -3.2 ([SIM] PROBE_SURFACE_Z), and
// optionally its X extent.
config::MachineConfig probing_mill(const std::string& sim_keys = "PROBE_SURFACE_Z = -3.2\n") {
  config::MachineConfig c = small_mill();
  const auto path = std::filesystem::temp_directory_path() /
                    ("cncd-probe-" + std::to_string(::getpid()) + ".ini");
  {
    std::ofstream out(path);
    out << "[SIM]\n" << sim_keys;
  }
  std::vector<config::Problem> problems, warnings;
  c.ini = std::make_shared<const config::IniFile>(config::IniFile::read(path, problems, warnings));
  std::filesystem::remove(path);
  EXPECT_TRUE(problems.empty());
  return c;
}

Move traverse(double x, double y, double z) {
  Move m;
  m.kind = Move::Kind::traverse;
  m.end = {x, y, z};
  m.path_mode = Move::PathMode::exact_stop;
  return m;
}

Move probe(double x, double y, double z, ProbeMode mode, double mm_per_min = 50) {
  Move m;
  m.kind = Move::Kind::feed;
  m.end = {x, y, z};
  m.feed = mm_per_min / 60;
  m.probe = mode;
  m.path_mode = Move::PathMode::exact_stop;
  return m;
}

class Probing : public ::testing::Test {
 protected:
  void start(const config::MachineConfig& config, double z) {
    machine_ = std::make_unique<VirtualMachine>(config);
    machine_->ready();
    machine_->queue(traverse(10, 20, z));
    machine_->run_until_idle();
    machine_->clear_trajectory();
  }
  motion::Status run(const Move& move) {
    machine_->queue(move);
    machine_->run_until_idle();
    return machine_->status();
  }
  std::unique_ptr<VirtualMachine> machine_;
};

TEST_F(Probing, G38_2StopsAtTheSurfaceAndLatchesWhereItTripped) {
  start(probing_mill(), 0);
  const auto s = run(probe(10, 20, -10, ProbeMode::toward_or_error));
  EXPECT_EQ(s.path_errors, 0U);
  EXPECT_EQ(s.probe.done, 1U);
  EXPECT_TRUE(s.probe.tripped);
  EXPECT_FALSE(s.probe.armed);
  // One period at 50 mm/min is 0.83 um: the latch is the first period at or below the top.
  EXPECT_LE(s.probe.position[2], -3.2);
  EXPECT_NEAR(s.probe.position[2], -3.2, 0.002);
  EXPECT_EQ(s.probe.position[0], 10);
  EXPECT_EQ(s.probe.position[1], 20);
  // The machine stopped a little further on, within the limits, far short of the end.
  EXPECT_LT(s.commanded[2], s.probe.position[2]);
  EXPECT_GT(s.commanded[2], -3.21);
  expect_within_limits(*machine_, {10, 20, 0});
  EXPECT_TRUE(s.probe.contact);
}

TEST_F(Probing, FastProbesStillStopWithinTheLimits) {
  start(probing_mill(), 0);
  const auto s = run(probe(10, 20, -10, ProbeMode::toward_or_error, 3000));
  EXPECT_TRUE(s.probe.tripped);
  EXPECT_NEAR(s.probe.position[2], -3.2, 0.05 + 1e-9);  // 50 mm/s: one period is 0.05 mm
  EXPECT_LT(s.commanded[2], -3.2);
  expect_within_limits(*machine_, {10, 20, 0});
}

TEST_F(Probing, G38_3WithoutContactEndsAtTheEndWithoutError) {
  start(probing_mill(), 0);
  const auto s = run(probe(10, 20, -1, ProbeMode::toward));
  EXPECT_EQ(s.path_errors, 0U);
  EXPECT_EQ(s.probe.done, 1U);
  EXPECT_FALSE(s.probe.tripped);
  EXPECT_NEAR(s.probe.position[2], -1, 1e-9);
  EXPECT_NEAR(s.commanded[2], -1, 1e-9);
}

TEST_F(Probing, G38_2WithoutContactIsAnError) {
  start(probing_mill(), 0);
  const auto s = run(probe(10, 20, -1, ProbeMode::toward_or_error));
  EXPECT_EQ(s.path_errors, 1U);
  EXPECT_EQ(s.path_error.code, RtEvent::Code::probe_no_contact);
  EXPECT_EQ(motion::format_event(s.path_error),
            "G38.2 probe move finished without tripping the probe");
  EXPECT_EQ(s.machine, motion::MachineState::on);
}

TEST_F(Probing, AProbeAlreadyTrippedDoesNotMove) {
  start(probing_mill(), -5);
  const auto s = run(probe(10, 20, -10, ProbeMode::toward));
  EXPECT_EQ(s.path_errors, 1U);
  EXPECT_EQ(s.path_error.code, RtEvent::Code::probe_tripped_at_start);
  EXPECT_EQ(s.probe.done, 0U);
  EXPECT_NEAR(s.commanded[2], -5, 0.001);  // one period at the probing feed at the most
}

TEST_F(Probing, G38_4BacksOffToWhereContactIsLost) {
  start(probing_mill(), -5);
  auto s = run(probe(10, 20, 0, ProbeMode::away_or_error));
  EXPECT_EQ(s.path_errors, 0U);
  EXPECT_TRUE(s.probe.tripped);
  EXPECT_GT(s.probe.position[2], -3.2);
  EXPECT_NEAR(s.probe.position[2], -3.2, 0.002);
  EXPECT_FALSE(s.probe.contact);
  // From above, away from contact is refused at the start; G38.4 that never loses it fails.
  s = run(probe(10, 20, 1, ProbeMode::away));
  EXPECT_EQ(s.path_error.code, RtEvent::Code::probe_untripped_at_start);
  s = run(traverse(10, 20, -8));
  s = run(probe(10, 20, -6, ProbeMode::away_or_error));
  EXPECT_EQ(s.path_error.code, RtEvent::Code::probe_contact_kept);
}

TEST_F(Probing, TheBlocksSideIsFoundAlongX) {
  start(probing_mill("PROBE_SURFACE_Z = -3.2\nPROBE_X_MIN = 50\n"), -5);
  // Beside the block at Z -5, toward its side at X 50.
  auto s = run(probe(80, 20, -5, ProbeMode::toward_or_error, 100));
  EXPECT_TRUE(s.probe.tripped);
  EXPECT_NEAR(s.probe.position[0], 50, 0.002);
  EXPECT_GE(s.probe.position[0], 50);
}

TEST_F(Probing, AbortEndsTheProbeWithoutAnOutcome) {
  start(probing_mill(), 0);
  machine_->queue(probe(10, 20, -1, ProbeMode::toward_or_error));
  machine_->flush();
  machine_->cycles(100);
  EXPECT_TRUE(machine_->status().probe.armed);
  machine_->command(motion::Command::Kind::abort);
  machine_->run_until_idle();
  const auto s = machine_->status();
  EXPECT_FALSE(s.probe.armed);
  EXPECT_EQ(s.probe.done, 0U);
  EXPECT_EQ(s.path_errors, 0U);
}

TEST_F(Probing, ForcedProbeInputOverridesTheModel) {
  start(small_mill(), 0);  // no model: the probe never trips by itself
  machine_->queue(probe(10, 20, -10, ProbeMode::toward_or_error));
  machine_->flush();
  machine_->cycles(600);  // 0.5 mm down
  machine_->sim().force_probe(1);
  machine_->run_until_idle();
  const auto s = machine_->status();
  EXPECT_TRUE(s.probe.tripped);
  EXPECT_NEAR(s.probe.position[2], -0.5, 0.01);
}

}  // namespace
}  // namespace cncd::test
