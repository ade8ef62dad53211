// The Interpreter's public behaviour beyond rs274 parity: stepping, files, startup code,
// parameter persistence, block delete, machine conversion of a whole program.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"
#include "cncd/interp/to_machine.hpp"

namespace cncd::interp {
namespace {

std::filesystem::path temp_file(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("cncd_interp_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path;
}

std::string run_text(Interpreter& interp, const std::string& program) {
  EXPECT_FALSE(interp.open_string(program, "t.ngc"));
  std::ostringstream out;
  Rs274Printer printer(out);
  const auto error = run_program(interp, printer);
  EXPECT_FALSE(error) << (error ? error->to_string() : "");
  return out.str();
}

TEST(InterpreterApi, StepReportsBlocksThenEndThenStaysEnded) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string("G0 X1\n\nM2\nG0 X5\n"));
  NullSink sink;
  EXPECT_EQ(interp.step(sink), Interpreter::Step::block);
  EXPECT_EQ(interp.current_line(), 1);
  EXPECT_EQ(interp.step(sink), Interpreter::Step::block);
  EXPECT_EQ(interp.step(sink), Interpreter::Step::end);
  EXPECT_EQ(interp.current_line(), 3);
  EXPECT_EQ(interp.step(sink), Interpreter::Step::end);
}

TEST(InterpreterApi, ErrorsCarryFileLineAndColumnAndStick) {
  Interpreter interp;
  ASSERT_FALSE(interp.open_string("G0 X1\nG0 X1 Y2 Y3\nM2\n", "part.ngc"));
  NullSink sink;
  EXPECT_EQ(interp.step(sink), Interpreter::Step::block);
  EXPECT_EQ(interp.step(sink), Interpreter::Step::error);
  ASSERT_TRUE(interp.error());
  EXPECT_EQ(interp.error()->to_string(), "part.ngc:2:10: Multiple y words on one line");
  EXPECT_EQ(interp.step(sink), Interpreter::Step::error);
}

TEST(InterpreterApi, ANewProgramStartsAfterAnErrorWithPositionKept) {
  Interpreter interp;
  NullSink sink;
  ASSERT_FALSE(interp.open_string("G0 X5\nG1 X1\nM2\n"));
  ASSERT_TRUE(run_program(interp, sink));  // no feed rate
  ASSERT_FALSE(interp.open_string("G91 G0 X1\nM2\n"));
  std::ostringstream out;
  Rs274Printer printer(out);
  EXPECT_FALSE(run_program(interp, printer));
  EXPECT_NE(out.str().find("STRAIGHT_TRAVERSE(6.0000, 0.0000, 0.0000"), std::string::npos);
}

TEST(InterpreterApi, UnreadableToolTableIsReportedAtOpen) {
  const auto table = temp_file("bad.tbl", "T1 P1 Zabc\n");
  InterpOptions options;
  options.tool_table = table;
  Interpreter interp(options);
  const auto error = interp.open_string("M2\n");
  ASSERT_TRUE(error);
  EXPECT_NE(error->message.find("bad value 'Zabc'"), std::string::npos) << error->message;
  std::filesystem::remove(table);
}

TEST(InterpreterApi, ReadsFilesWithCrLfAndSubroutineFiles) {
  const auto sub =
      temp_file("sub.ngc", "o<cncd_square> sub\r\nG1 X#1 F100\r\no<cncd_square> endsub\r\n");
  const auto renamed = sub.parent_path() / "cncd_square.ngc";
  std::filesystem::rename(sub, renamed);
  const auto program = temp_file("main.ngc", "%\r\no<cncd_square> call [4]\r\nG0 Y1\r\n%\r\n");
  Interpreter interp;
  ASSERT_FALSE(interp.open(program));
  std::ostringstream out;
  Rs274Printer printer(out);
  const auto error = run_program(interp, printer);
  EXPECT_FALSE(error) << (error ? error->to_string() : "");
  EXPECT_NE(out.str().find("STRAIGHT_FEED(4.0000, 0.0000, 0.0000"), std::string::npos);
  EXPECT_NE(out.str().find("STRAIGHT_TRAVERSE(4.0000, 1.0000, 0.0000"), std::string::npos);
  EXPECT_NE(out.str().find("FINISH()"), std::string::npos);
  std::filesystem::remove(renamed);
  std::filesystem::remove(program);
}

TEST(InterpreterApi, MissingFileIsAnError) {
  Interpreter interp;
  const auto error = interp.open("/nonexistent/cncd/part.ngc");
  ASSERT_TRUE(error);
  EXPECT_EQ(error->message, "Unable to open file: No such file or directory");
}

TEST(InterpreterApi, StartupCodeRunsBeforeTheProgram) {
  InterpOptions options;
  options.startup_code = "G20 G91\nF5";
  Interpreter interp(options);
  const std::string out = run_text(interp, "G1 X1\nG1 X1\nM2\n");
  EXPECT_NE(out.find("USE_LENGTH_UNITS(CANON_UNITS_INCHES)"), std::string::npos);
  EXPECT_NE(out.find("STRAIGHT_FEED(2.0000, 0.0000, 0.0000"), std::string::npos);
}

TEST(InterpreterApi, BlockDeleteSkipsSlashLinesOnlyWhenEnabled) {
  InterpOptions options;
  options.block_delete = true;
  Interpreter with(options);
  EXPECT_EQ(run_text(with, "/G0 X1\nM2\n").find("STRAIGHT_TRAVERSE"), std::string::npos);
  Interpreter without;
  EXPECT_NE(run_text(without, "/G0 X1\nM2\n").find("STRAIGHT_TRAVERSE"), std::string::npos);
}

TEST(InterpreterApi, ParametersPersistThroughTheVarFile) {
  const auto var = temp_file("params.var", "5220 1\n");
  {
    InterpOptions options;
    options.parameter_file = var;
    Interpreter interp(options);
    run_text(interp, "G10 L2 P2 X5 Y-2 R30\nG28.1\nM2\n");
    EXPECT_FALSE(interp.save_parameters());
  }
  InterpOptions options;
  options.parameter_file = var;
  Interpreter interp(options);
  const std::string out = run_text(interp, "G55\nM2\n");
  EXPECT_NE(out.find("SET_G5X_OFFSET(2, 5.0000, -2.0000, 0.0000"), std::string::npos);
  EXPECT_NE(out.find("SET_XY_ROTATION(30.0000)"), std::string::npos);
  std::filesystem::remove(var);
}

// The parameter file's place is taken by a directory: the rename fails, and the temporary
// file it would have replaced the file with is gone too.
TEST(InterpreterApi, AFailedParameterSaveLeavesNoTemporaryFile) {
  const auto dir = temp_file("blocked", "");
  std::filesystem::remove(dir);
  const auto var = dir / "params.var";
  std::filesystem::create_directories(dir);
  InterpOptions options;
  options.parameter_file = var;
  Interpreter interp(options);  // no file yet: the defaults, and the file is made at save
  std::filesystem::create_directories(var / "in_the_way");
  const auto error = interp.save_parameters();
  ASSERT_TRUE(error);
  EXPECT_NE(error->message.find("Unable to replace parameter file"), std::string::npos)
      << error->to_string();
  // The parameter file's place (a directory now) and nothing else: no temporary file.
  std::vector<std::string> left;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"params.var"});
  std::filesystem::remove_all(dir);
}

TEST(InterpreterApi, RestoredParametersPutTheOffsetsAndCoordinateSystemBack) {
  Interpreter interp;
  NullSink sink;
  const std::vector<double> saved = interp.persistent_parameters();
  for (const char* line : {"G10 L2 P1 X5", "G92 X1", "G55"}) {
    ASSERT_FALSE(interp.open_mdi(line));
    ASSERT_FALSE(run_program(interp, sink));
  }
  EXPECT_NE(interp.persistent_parameters(), saved);
  EXPECT_EQ(interp.state().coord_system, 2);
  interp.restore_persistent_parameters(saved);
  EXPECT_EQ(interp.persistent_parameters(), saved);
  const InterpState st = interp.state();
  EXPECT_EQ(st.coord_system, 1);
  EXPECT_EQ(st.g5x_offset[0], 0.0);
  EXPECT_EQ(st.g92_offset[0], 0.0);
  // The canon layer learns the offsets again before the next move.
  ASSERT_FALSE(interp.open_mdi("G0 X2"));
  std::ostringstream out;
  Rs274Printer printer(out);
  ASSERT_FALSE(run_program(interp, printer));
  EXPECT_NE(out.str().find("SET_G5X_OFFSET(1, 0.0000"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("SET_G92_OFFSET(0.0000"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("STRAIGHT_TRAVERSE(2.0000"), std::string::npos) << out.str();
}

// A '%' alone in MDI does nothing, after a program delimited by '%' as before any program.
TEST(InterpreterApi, APercentInMdiDoesNothing) {
  Interpreter interp;
  std::ostringstream out;
  Rs274Printer printer(out);
  for (int pass = 0; pass < 2; ++pass) {
    ASSERT_FALSE(interp.open_mdi("%"));
    ASSERT_FALSE(run_program(interp, printer));
    ASSERT_FALSE(interp.open_string("\n%\nG0 X1\n%\n", "p.ngc"));
    ASSERT_FALSE(run_program(interp, printer));
  }
  ASSERT_FALSE(interp.open_mdi("%"));
  ASSERT_FALSE(run_program(interp, printer));
  ASSERT_FALSE(interp.open_mdi("G0 X3"));
  ASSERT_FALSE(run_program(interp, printer));
  const std::string canon = out.str();
  std::size_t finishes = 0;
  for (auto at = canon.find("FINISH()"); at != std::string::npos;
       at = canon.find("FINISH()", at + 1))
    ++finishes;
  EXPECT_EQ(finishes, 2U) << canon;  // the programs' own
  EXPECT_NE(canon.find("STRAIGHT_TRAVERSE(3.0000"), std::string::npos) << canon;
}

TEST(InterpreterApi, SetToolsReplacesTheWholeTable) {
  Interpreter interp;
  ToolEntry three;
  three.number = 3;
  three.offset[2] = 7;
  interp.set_tool(three);
  ToolEntry five;
  five.number = 5;
  interp.set_tools({five});
  EXPECT_FALSE(interp.tool(3));
  ASSERT_TRUE(interp.tool(5));
  EXPECT_EQ(interp.tools().size(), 1u);
}

TEST(InterpreterApi, MachinePositionIsSeenThroughTheOffsets) {
  // G54 X offset 10 mm on an inch program: machine X 35.4 mm is program X 1 inch.
  const auto vars = temp_file("machine_pos.var", "5221\t10.000000\n");
  InterpOptions options;
  options.parameter_file = vars;
  Interpreter interp(options);
  ASSERT_FALSE(interp.open_string("G20 G91 G0 X1\nM2\n", "t.ngc"));
  interp.set_machine_position({35.4, 0, 0, 0, 0, 0, 0, 0, 0});
  std::ostringstream out;
  Rs274Printer printer(out);
  ASSERT_FALSE(run_program(interp, printer));
  EXPECT_NE(out.str().find("STRAIGHT_TRAVERSE(2.0000, 0.0000, 0.0000"), std::string::npos)
      << out.str();
  std::filesystem::remove(vars);
}

TEST(InterpreterApi, MdiKeepsModalStateAndNeedsNoProgramEnd) {
  Interpreter interp;
  std::ostringstream out;
  Rs274Printer printer(out);
  ASSERT_FALSE(interp.open_mdi("G21 G91 G1 F100 X1"));
  ASSERT_FALSE(run_program(interp, printer));
  ASSERT_FALSE(interp.open_mdi("X2"));  // still G91 G1 at F100
  ASSERT_FALSE(run_program(interp, printer));
  EXPECT_NE(out.str().find("STRAIGHT_FEED(3.0000, 0.0000"), std::string::npos) << out.str();
  ASSERT_FALSE(interp.open_mdi("G1 X"));
  EXPECT_TRUE(run_program(interp, printer).has_value());
  // An error does not stick to the next line.
  ASSERT_FALSE(interp.open_mdi("X1"));
  EXPECT_FALSE(run_program(interp, printer).has_value());
}

// The whole path the daemon uses: program -> canon -> MachineTracker -> machine moves.
TEST(InterpreterApi, MachineTrackerFollowsOffsetsUnitsAndToolLength) {
  struct Machine final : CanonSink {
    void emit(const CanonCommand& command) override {
      const CanonCommand m = tracker.to_machine(command);
      std::optional<Pose> end;
      if (const auto* arc = std::get_if<ArcFeed>(&m.op)) {
        arcs.push_back(*arc);
        end = arc->end();
      } else if (const auto* traverse = std::get_if<StraightTraverse>(&m.op)) {
        end = traverse->end;
      } else if (const auto* feed = std::get_if<StraightFeed>(&m.op)) {
        end = feed->end;
      }
      if (end) {
        moves.push_back(*end);
        feeds.push_back(tracker.feed_per_minute());
      }
    }
    MachineTracker tracker{Units::mm};
    std::vector<Pose> moves;  // end points
    std::vector<ArcFeed> arcs;
    std::vector<double> feeds;
  } machine;
  Interpreter interp;
  ASSERT_FALSE(interp.open_string(
      "G10 L2 P2 X10 Y20 Z30\nG55 G20\nF10\nG1 X1 Y1 Z1\nG92 X0\nG1 X1\nG43.1 Z0.5\n"
      "G1 Z0\nG2 X2 Y1 I0.5 J0\nM2\n"));
  const auto error = run_program(interp, machine);
  ASSERT_FALSE(error) << error->to_string();
  ASSERT_EQ(machine.moves.size(), 4U);
  EXPECT_NEAR(machine.moves[0][0], 10 + 25.4, 1e-9);
  EXPECT_NEAR(machine.moves[0][1], 20 + 25.4, 1e-9);
  EXPECT_NEAR(machine.moves[0][2], 30 + 25.4, 1e-9);
  EXPECT_NEAR(machine.feeds[0], 254.0, 1e-9);
  EXPECT_NEAR(machine.moves[1][0], 10 + 2 * 25.4, 1e-9);    // G92 shifted X by 1 inch
  EXPECT_NEAR(machine.moves[2][2], 30 + 0.5 * 25.4, 1e-9);  // tool length offset
  ASSERT_EQ(machine.arcs.size(), 1U);
  const ArcFeed& arc = machine.arcs[0];
  EXPECT_NEAR(arc.first_end, 10 + 3 * 25.4, 1e-9);
  EXPECT_NEAR(arc.first_axis, 10 + 2.5 * 25.4, 1e-9);
  EXPECT_NEAR(arc.second_axis, 20 + 25.4, 1e-9);
  EXPECT_EQ(arc.rotation, -1);
}

}  // namespace
}  // namespace cncd::interp
