// Interpreter::state() and the changes made between programs: coordinate system origins and
// tool table entries.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

#include "cncd/interp/interpreter.hpp"
#include "cncd/interp/rs274_printer.hpp"

namespace cncd::interp {
namespace {

// One MDI block: the modal state stays as the block leaves it (a program's M2 would reset it).
void run(Interpreter& interp, const std::string& block) {
  ASSERT_FALSE(interp.open_mdi(block));
  NullSink sink;
  const auto error = run_program(interp, sink);
  ASSERT_FALSE(error) << error->to_string();
}

TEST(InterpreterState, ActiveCodesAsLinuxCncNumbersThem) {
  Interpreter interp;
  run(interp, "G20 G91 G18 G59.1 G61.1 G98 G93 F1 G1 X1 M3 S100 M7");
  const InterpState s = interp.state();
  // {index, code}
  for (const auto& [index, code] : {std::pair{1, 10},
                                    {3, 180},
                                    {5, 200},
                                    {6, 910},
                                    {7, 930},
                                    {8, 591},
                                    {9, 490},
                                    {10, 980},
                                    {11, 611},
                                    {16, -1}})
    EXPECT_EQ(s.gcodes[index], code) << "gcodes[" << index << "]";
  for (const auto& [index, code] : {std::pair{2, 3}, {4, 7}, {5, -1}})
    EXPECT_EQ(s.mcodes[index], code) << "mcodes[" << index << "]";
  EXPECT_EQ(s.coord_system, 7);
  EXPECT_EQ(s.speed, 100.0);
}

TEST(InterpreterState, OffsetsAreReportedInMachineUnits) {
  Interpreter interp;  // a mm machine
  run(interp, "G20 G10 L2 P1 X1");
  run(interp, "G92 Y0");
  run(interp, "G43.1 Z2");
  const InterpState s = interp.state();
  EXPECT_DOUBLE_EQ(s.g5x_offset[0], 25.4);
  EXPECT_DOUBLE_EQ(s.tool_offset[2], 50.8);
  EXPECT_EQ(s.gcodes[9], 430);
  EXPECT_EQ(s.gcodes[16], 923);
  // The G92 offset makes the point Y0 read Y0: zero, as the machine started there.
  EXPECT_DOUBLE_EQ(s.g92_offset[1], 0.0);
}

TEST(InterpreterState, SetCoordSystemOriginActsLikeG10L2) {
  Interpreter interp;
  ASSERT_FALSE(interp.set_coord_system_origin(2, Pose{5, 6, 7}, 0b101, 30.0));
  double rotation = 0;
  const Pose origin = interp.coord_system_origin(2, &rotation);
  EXPECT_EQ(origin[0], 5.0);
  EXPECT_EQ(origin[1], 0.0);  // Y not in the mask
  EXPECT_EQ(origin[2], 7.0);
  EXPECT_EQ(rotation, 30.0);
  run(interp, "G55");
  EXPECT_EQ(interp.state().g5x_offset[0], 5.0);
  EXPECT_EQ(interp.state().rotation_deg, 30.0);
  // A change to the active system reaches the canonical stream before the next block's moves.
  ASSERT_FALSE(interp.set_coord_system_origin(2, Pose{8}, 0b1, std::nullopt));
  ASSERT_FALSE(interp.open_mdi("G0 X0"));
  std::ostringstream out;
  Rs274Printer printer(out);
  ASSERT_FALSE(run_program(interp, printer));
  const std::string canon = out.str();
  const auto g5x = canon.find("SET_G5X_OFFSET(2, 8.0000");
  EXPECT_NE(g5x, std::string::npos) << canon;
  EXPECT_LT(g5x, canon.find("STRAIGHT_TRAVERSE")) << canon;
}

TEST(InterpreterState, ToolTableKeepsCommentsAndTakesNewEntries) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("cncd_state_" + std::to_string(::getpid()) + ".tbl");
  std::ofstream(path) << "T1 P1 D6 Z+1.5 ;  6 mm end mill  \nT3 P3 Z2\n";
  InterpOptions options;
  options.tool_table = path;
  Interpreter interp(options);
  auto tools = interp.tools();
  ASSERT_EQ(tools.size(), 2u);
  EXPECT_EQ(tools[0].comment, "6 mm end mill");
  EXPECT_EQ(tools[0].offset[2], 1.5);
  ToolEntry t2;
  t2.number = 2;
  t2.pocket = 2;
  t2.offset[2] = 4;
  ASSERT_FALSE(interp.set_tool(t2));
  run(interp, "T2 M6 G43");
  EXPECT_EQ(interp.state().tool_in_spindle, 2);
  EXPECT_EQ(interp.state().tool_offset[2], 4.0);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace cncd::interp
