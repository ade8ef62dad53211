// Planner benchmark: cycle time of the real planner and servo loop (plan_sim, virtual time)
// over the feed-limited bound on a small fast mill, peak axis velocity and acceleration over
// the limits, path deviation and CPU time per move; side by side with LinuxCNC running the
// same programs on the same limits (through the LinuxCNC bench harness run.sh, in real time,
// when it is there: --run-sh, else $CNCD_LINUXCNC_BENCH, else
// ../shared/tools/linuxcnc-bench/run.sh beside the source tree). Programs and INIs are generated
// (planner_programs.cpp).
//
// For a program with a dense blended path (the raster's rows, the circle's chords, the cut of
// 3D_Chips) it also prints the path alone against its own feed-limited bound and the floors of
// path_floor.hpp: the time from the start of its first move to the end of its last within the
// whole program (from the simulation's per-move start times), and the path run alone from
// rest where it starts (a program of its lines after G92), on cncd and LinuxCNC, and the
// time-optimal reference of path_reference.hpp on its exact path and within its G64 P (and the
// other geometries within P of path_smooth.hpp); for 3D_Chips and the surface finish, where the
// time goes (path_diagnosis.hpp).
//
//   cncd_planner_bench [--no-linuxcnc] [--keep] [--run-sh PATH] [--jerk J] [--only TEXT]
//                      [--speed-svg FILE [--speed-window FROM,TO]]
//
// --only TEXT runs the programs whose name contains TEXT.
//
// --jerk J runs cncd with S-curve profiles ([TRAJ] MAX_LINEAR_JERK = J mm/s^3) and without
// LinuxCNC, whose 2.9 planner has none (the floors stay those of trapezoids).
//
// --speed-svg FILE writes the picture of speed_svg.hpp for the first program with a diagnosis
// (3D_Chips when it is there): the path speed against path length along the path alone,
// cncd's from the servo loop's samples, the reference's within P, Q and the programmed feed,
// from FROM to TO mm of the path (--speed-window), by default over the 40 mm where cncd
// takes the most time over the reference.
//
// A benchmark: it prints figures and never fails on them.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cncd/config/machine_config.hpp"
#include "cncd/pipeline/plan_sim.hpp"
#include "path_diagnosis.hpp"
#include "path_floor.hpp"
#include "path_reference.hpp"
#include "path_smooth.hpp"
#include "planner_programs.hpp"
#include "speed_svg.hpp"

namespace {

namespace fs = std::filesystem;
constexpr const char* kAxisMm =
    "/usr/share/doc/linuxcnc/examples/sample-configs/sim/axis/axis_mm.ini";
constexpr const char* kChips = "/usr/share/doc/linuxcnc/examples/nc_files/3D_Chips.ngc";
std::string default_run_sh() {
  if (const char* env = std::getenv("CNCD_LINUXCNC_BENCH"); env != nullptr && *env != '\0') {
    return env;
  }
  return (std::filesystem::path(CNCD_SOURCE_DIR).parent_path() /
          "shared/tools/linuxcnc-bench/run.sh")
      .string();
}

struct LinuxcncRun {
  double run_s = 0;     // cycle start until the interpreter is idle
  double moving_s = 0;  // servo cycles with the machine out of position
};

// Runs LinuxCNC's harness; nullopt (with what it said) when it fails.
std::optional<LinuxcncRun> run_linuxcnc(const std::string& run_sh, const fs::path& ini,
                                        const fs::path& program, const fs::path& log) {
  const std::string command = "BENCH_TIMEOUT=600 '" + run_sh + "' '" + ini.string() + "' '" +
                              program.string() + "' >'" + log.string() + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  LinuxcncRun run;
  bool found = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("linuxcnc_run_s=", 0) == 0) {
      run.run_s = std::atof(line.c_str() + 15);
      found = true;
    } else if (line.rfind("# moving_s=", 0) == 0) {
      run.moving_s = std::atof(line.c_str() + 11);
    }
  }
  if (status != 0 || !found) {
    std::fprintf(stderr, "  LinuxCNC run failed (%s): see %s\n", program.c_str(), log.c_str());
    return std::nullopt;
  }
  return run;
}

double worst_ratio(const cncd::config::MachineConfig& machine, const cncd::motion::AxisPose& peaks,
                   bool acceleration) {
  double worst = 0;
  for (std::size_t i = 0; i < cncd::config::kAxisLetters.size(); ++i) {
    const auto& axis = machine.axes[i];
    if (!axis.present) continue;
    worst = std::max(worst, peaks[i] / (acceleration ? axis.max_acceleration : axis.max_velocity));
  }
  return worst;
}

struct Bench {
  const cncd::config::MachineConfig& machine;
  fs::path dir;
  bool linuxcnc = false;
  std::string run_sh;
  fs::path lcnc_ini;
  fs::path speed_svg;                               // --speed-svg, empty: none
  std::optional<cncd::bench::Window> speed_window;  // --speed-window
  mutable bool pictured = false;

  cncd::pipeline::PlanSimResult simulate(
      const fs::path& program, std::vector<cncd::motion::Segment>* path_moves = nullptr,
      int first_line = 0, int last_line = 0, std::vector<cncd::motion::Segment>* segments = nullptr,
      std::vector<cncd::motion::AxisPose>* samples = nullptr) const {
    cncd::pipeline::PlanSimOptions options;
    if (samples != nullptr)
      options.on_sample = [samples](double, const cncd::motion::AxisPose& at, double) {
        samples->push_back(at);
      };
    options.interp = cncd::pipeline::interpreter_options(machine);
    options.start_machine = cncd::interp::Pose{};
    if (segments != nullptr)
      options.on_segment = [segments](const cncd::motion::Segment& s) { segments->push_back(s); };
    if (path_moves != nullptr)
      options.on_move = [&](const cncd::motion::Segment& move) {
        if (move.line >= first_line && move.line <= last_line) path_moves->push_back(move);
      };
    return cncd::pipeline::simulate_plan(machine, program, options);
  }

  std::optional<LinuxcncRun> linuxcnc_run(const fs::path& program) const {
    if (!linuxcnc) return std::nullopt;
    std::fflush(stdout);
    const fs::path log = dir / (program.stem().string() + ".linuxcnc.log");
    return run_linuxcnc(run_sh, lcnc_ini, program, log);
  }

  void whole(const cncd::bench::BenchProgram& program,
             const cncd::pipeline::PlanSimResult& r) const {
    const double moves = static_cast<double>(r.moves);
    std::printf("  whole program\n    cncd      cycle %.3f s  feed bound %.3f s  ratio %.4f",
                r.cycle_time_s, r.feed_bound_s, r.cycle_time_s / r.feed_bound_s);
    if (program.exact_stop)
      std::printf("  exact-stop bound %.3f s  ratio %.4f", r.exact_stop_bound_s,
                  r.cycle_time_s / r.exact_stop_bound_s);
    std::printf(
        "\n              peak v %.3f %%  peak a %.3f %% (worst axis, of its limit)  "
        "X/Y/Z a %.1f/%.1f/%.1f %%  max deviation %.4f mm\n",
        100 * worst_ratio(machine, r.peak_velocity, false),
        100 * worst_ratio(machine, r.peak_acceleration, true),
        100 * r.peak_acceleration[0] / machine.axes[0].max_acceleration,
        100 * r.peak_acceleration[1] / machine.axes[1].max_acceleration,
        100 * r.peak_acceleration[2] / machine.axes[2].max_acceleration, r.max_deviation);
    std::printf(
        "              %zu moves; CPU per move: planner %.3f us, servo loop %.3f us "
        "(%.3f us per period); simulated in %.2f s\n",
        r.moves, r.planner_cpu_s * 1e6 / moves, r.servo_cpu_s * 1e6 / moves,
        r.servo_cpu_s * 1e6 / static_cast<double>(r.cycles), r.wall_s);
    if (const auto l = linuxcnc_run(program.path)) {
      std::printf("    LinuxCNC  run %.3f s (moving %.3f s)  ratio %.4f", l->run_s, l->moving_s,
                  l->run_s / r.feed_bound_s);
      if (program.exact_stop)
        std::printf("  over exact-stop bound %.4f", l->run_s / r.exact_stop_bound_s);
      std::printf("  cncd/LinuxCNC %.4f\n", r.cycle_time_s / l->run_s);
    }
  }

  // The dense path: within the program (per-move start times) and alone, on both controllers.
  void path(const cncd::bench::BenchProgram& program, const cncd::pipeline::PlanSimResult& r,
            const std::vector<cncd::motion::Segment>& moves) const {
    std::size_t first = r.move_line.size();
    std::size_t last = 0;
    for (std::size_t i = 0; i < r.move_line.size(); ++i) {
      if (r.move_line[i] == program.path_first_line && first == r.move_line.size()) first = i;
      if (r.move_line[i] == program.path_last_line) last = i;
    }
    if (moves.empty() || first >= r.move_line.size() || last < first) {
      std::printf("  path: lines %d..%d not found among the moves\n", program.path_first_line,
                  program.path_last_line);
      return;
    }
    const double end_s =
        last + 1 < r.move_start_s.size() ? r.move_start_s[last + 1] : r.cycle_time_s;
    const double in_program_s = end_s - r.move_start_s[first];
    const auto floors = cncd::bench::path_floors(machine, moves);
    std::printf(
        "  blended path alone: lines %d..%d, %zu moves, %.1f mm\n"
        "    feed bound %.3f s   start/stop floor %.3f s (%.4f x bound)   exact-path floor %.3f s "
        "(%.4f x bound)\n",
        program.path_first_line, program.path_last_line, moves.size(), floors.length,
        floors.bound_s, floors.start_stop_s, floors.start_stop_s / floors.bound_s,
        floors.exact_path_s, floors.exact_path_s / floors.bound_s);
    cncd::bench::ReferenceOptions exact;
    cncd::bench::ReferenceOptions within;
    within.blend_corners = true;
    within.tolerance = program.tolerance;
    cncd::bench::ReferenceOptions merged = within;
    merged.merge_tolerance = program.merge_tolerance;
    const bool picture = program.diagnose && !speed_svg.empty() && !pictured;
    merged.profile = picture;
    const auto started = std::chrono::steady_clock::now();
    const auto ref_exact = cncd::bench::time_optimal(machine, moves, exact);
    const auto ref_within = cncd::bench::time_optimal(machine, moves, within);
    const auto ref = cncd::bench::time_optimal(machine, moves, merged);
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - started;
    const auto change = [&](cncd::bench::ReferenceOptions o, const cncd::bench::PathReference& at) {
      o.max_step /= 2;
      o.max_turn /= 2;
      return 100 * (cncd::bench::time_optimal(machine, moves, o).time_s / at.time_s - 1);
    };
    std::printf(
        "    time-optimal reference: exact path %.3f s (%.4f x bound, %zu corner stops)   "
        "within P%g %.3f s (%.4f x bound, %zu blends)   within P%g Q%g %.3f s (%.4f x bound, "
        "%zu blends)\n"
        "      %zu, %zu and %zu grid steps in %.2f s; halving the grid changes them by %+.3f %%, "
        "%+.3f %% and %+.3f %%\n",
        ref_exact.time_s, ref_exact.time_s / floors.bound_s, ref_exact.stops, program.tolerance,
        ref_within.time_s, ref_within.time_s / floors.bound_s, ref_within.blends, program.tolerance,
        program.merge_tolerance, ref.time_s, ref.time_s / floors.bound_s, ref.blends,
        ref_exact.steps, ref_within.steps, ref.steps, took.count(), change(exact, ref_exact),
        change(within, ref_within), change(merged, ref));
    cncd::bench::print_smoothed(machine, moves, program.tolerance, program.merge_tolerance,
                                floors.bound_s);
    const auto ratios = [&floors, &ref](const char* who, const char* how, double s) {
      std::printf(
          "    %-9s %-18s %.3f s  ratio %.4f  over start/stop floor %.4f  "
          "over exact-path floor %.4f  over reference within P, Q %.4f\n",
          who, how, s, s / floors.bound_s, s / floors.start_stop_s, s / floors.exact_path_s,
          s / ref.time_s);
    };
    ratios("cncd", "in the program", in_program_s);
    const fs::path alone = cncd::bench::write_path_alone(program, dir, moves.front().start);
    if (alone.empty()) {
      std::printf("    (cannot write the path alone)\n");
      return;
    }
    std::vector<cncd::motion::Segment> segments;
    std::vector<cncd::motion::AxisPose> samples;
    const auto a = simulate(alone, nullptr, 0, 0, &segments, picture ? &samples : nullptr);
    if (!a.complete()) {
      std::printf("    cncd alone: %s\n",
                  (a.error ? a.error->to_string() : a.stopped->to_string()).c_str());
      return;
    }
    ratios("cncd", "alone", a.cycle_time_s);
    if (std::abs(a.feed_bound_s - floors.bound_s) > 1e-6 * floors.bound_s)
      std::printf("    (the path alone's feed bound is %.3f s)\n", a.feed_bound_s);
    if (program.diagnose && a.move_start_s.size() == moves.size()) {
      std::vector<double> cncd_s(moves.size());
      for (std::size_t i = 0; i < moves.size(); ++i)
        cncd_s[i] =
            (i + 1 < moves.size() ? a.move_start_s[i + 1] : a.cycle_time_s) - a.move_start_s[i];
      cncd::bench::print_diagnosis(
          machine, moves, program.merge_tolerance, cncd_s, ref,
          cncd::bench::planned_optimal(machine, segments, moves.size()),
          cncd::bench::planned_optimal(machine, segments, moves.size(), true));
    }
    if (picture) picture_speed(program, moves, ref, samples);
    if (const auto l = linuxcnc_run(alone)) {
      ratios("LinuxCNC", "alone (moving)", l->moving_s);
      std::printf("    cncd/LinuxCNC alone %.4f (LinuxCNC run, cycle start to idle, %.3f s)\n",
                  a.cycle_time_s / l->moving_s, l->run_s);
    }
  }

  // --speed-svg: cncd's speed from its samples (XYZ, per servo period), the reference's, the
  // feed of the move the reference's point counts in.
  void picture_speed(const cncd::bench::BenchProgram& program,
                     const std::vector<cncd::motion::Segment>& moves,
                     const cncd::bench::PathReference& ref,
                     const std::vector<cncd::motion::AxisPose>& samples) const {
    pictured = true;
    const auto picture = cncd::bench::write_speed_picture(
        speed_svg, program.name, static_cast<double>(machine.servo_period_ns) * 1e-9, moves,
        ref.profile, samples, speed_window);
    std::printf(
        "    speed picture: %s (s %.1f .. %.1f mm of %.1f mm; cncd's samples end at %.1f mm): "
        "cncd %.3f s, reference %.3f s there\n",
        speed_svg.c_str(), picture.window.from, picture.window.to, picture.reference_length,
        picture.cncd_length, picture.cncd_s, picture.reference_s);
  }
};

}  // namespace

int main(int argc, char** argv) {
  bool linuxcnc = true;
  bool keep = false;
  double jerk = 0;
  std::string only;
  std::string run_sh = default_run_sh();
  fs::path speed_svg;
  std::optional<cncd::bench::Window> speed_window;
  cncd::bench::Window window;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--no-linuxcnc") {
      linuxcnc = false;
    } else if (arg == "--keep") {
      keep = true;
    } else if (arg == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (arg == "--speed-svg" && i + 1 < argc) {
      speed_svg = argv[++i];
    } else if (arg == "--speed-window" && i + 1 < argc &&
               std::sscanf(argv[i + 1], "%lf,%lf", &window.from, &window.to) == 2 &&
               window.to > window.from) {
      speed_window = window;
      ++i;
    } else if (arg == "--run-sh" && i + 1 < argc) {
      run_sh = argv[++i];
    } else if (arg == "--jerk" && i + 1 < argc && std::atof(argv[i + 1]) >= 1) {
      jerk = std::atof(argv[++i]);
      linuxcnc = false;
    } else {
      std::fprintf(stderr,
                   "usage: cncd_planner_bench [--no-linuxcnc] [--keep] [--run-sh PATH] "
                   "[--jerk J (>= 1 mm/s^3)] [--only TEXT]\n"
                   "       [--speed-svg FILE [--speed-window FROM,TO (mm of path length)]]\n"
                   "  --speed-svg: SVG picture of the path speed along the first diagnosed path "
                   "(3D_Chips): cncd, the time-optimal reference within P, Q, the feed\n");
      return 64;
    }
  }
  char pattern[] = "/tmp/cncd-planner-bench-XXXXXX";
  if (mkdtemp(pattern) == nullptr) {
    std::perror("mkdtemp");
    return 1;
  }
  const fs::path dir = pattern;
  const fs::path ini = cncd::bench::write_cncd_ini(dir);
  const auto loaded = cncd::config::load_machine_config(ini);
  if (!loaded.ok()) {
    for (const auto& problem : loaded.problems)
      std::fprintf(stderr, "%s\n", problem.to_string().c_str());
    return 1;
  }
  auto machine = *loaded.config;
  if (jerk > 0) {
    machine.max_linear_jerk = jerk;
    machine.scurve = true;
  }
  const auto programs = cncd::bench::write_programs(dir, kChips);
  std::error_code ec;
  std::string lcnc_error;
  fs::path lcnc_ini;
  if (linuxcnc && access(run_sh.c_str(), X_OK) != 0) {
    std::printf("LinuxCNC: %s not found, cncd only\n", run_sh.c_str());
    linuxcnc = false;
  }
  if (linuxcnc) {
    lcnc_ini = cncd::bench::write_linuxcnc_ini(dir, kAxisMm, lcnc_error);
    if (lcnc_ini.empty()) {
      std::printf("LinuxCNC: %s, cncd only\n", lcnc_error.c_str());
      linuxcnc = false;
    }
  }
#ifdef NDEBUG
  const char* build = "optimised build";
#else
  const char* build = "debug build: CPU figures are pessimistic";
#endif
  std::printf(
      "machine: X/Y 200 mm/s 2000 mm/s^2, Z 100 mm/s 1000 mm/s^2, 1 ms servo period, %s (%s)\n"
      "files in %s\n\n",
      jerk > 0
          ? ("S-curve profiles, path jerk " + std::to_string(static_cast<long>(jerk)) + " mm/s^3")
                .c_str()
          : "trapezoidal profiles",
      build, dir.c_str());
  const Bench bench{machine, dir, linuxcnc, run_sh, lcnc_ini, speed_svg, speed_window};
  for (const auto& program : programs) {
    if (program.name.find(only) == std::string::npos) continue;
    std::printf("%s  (%s)\n", program.name.c_str(), program.path.filename().c_str());
    std::vector<cncd::motion::Segment> path_moves;
    const auto r =
        bench.simulate(program.path, &path_moves, program.path_first_line, program.path_last_line);
    if (!r.complete()) {
      std::printf("  cncd: %s\n\n",
                  (r.error ? r.error->to_string() : r.stopped->to_string()).c_str());
      continue;
    }
    bench.whole(program, r);
    if (program.path_first_line > 0) bench.path(program, r, path_moves);
    std::printf("\n");
    std::fflush(stdout);
  }
  if (!keep) fs::remove_all(dir, ec);
  return 0;
}
